//! The value parsers of the flags: each turns one flag's text into its
//! value or a message saying what is wrong with it, which clap prints
//! after the flag's name. Also [`one_line_error`], which puts a clap error
//! on one line.

// The numbers of `LO,HI` and `P,Q`, as an overlay's options read them too.
use volray_app::words::{finite, numbers, parse_pair};
pub use volray_app::words::{parse_opacity, parse_range};
use volray_core::{MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE};

/// A clap error as one line: its first, with the arguments it lists on the
/// lines below when the first ends in a colon ("the following required
/// arguments were not provided:"), so that the line names the flag.
pub fn one_line_error(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let mut lines = text.lines();
    let first = lines
        .next()
        .unwrap_or("error: invalid arguments")
        .trim_end();
    match first.strip_suffix(':') {
        Some(head) => {
            let listed: Vec<&str> = lines
                .take_while(|l| l.starts_with("  "))
                .map(str::trim)
                .collect();
            format!("{head}: {}", listed.join(", "))
        }
        None => first.to_string(),
    }
}

/// Finite and within `f32`'s range, for values the renderer keeps as `f32`.
fn finite_f32(values: Vec<f64>) -> Result<Vec<f64>, String> {
    let values = finite(values)?;
    match values.iter().find(|v| v.abs() > f32::MAX as f64) {
        Some(v) => Err(format!("{v} is beyond the range of 32-bit floats")),
        None => Ok(values),
    }
}

pub fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    let v = finite(numbers::<f64>(s, "number")?)?;
    <[f64; 3]>::try_from(v).map_err(|v| format!("expected X,Y,Z (three numbers), got {}", v.len()))
}

/// The smallest and largest voxel spacing `--spacing` takes, and the most
/// one axis's may exceed another's: beyond these the world box's squared
/// extents leave `f64`, or a ray along the coarse axis would take more
/// samples of the fine one than the renderer allows.
const SPACING_LIMITS: (f64, f64) = (1e-30, 1e30);
const MAX_SPACING_RATIO: f64 = 1e6;

pub fn parse_spacing(s: &str) -> Result<[f64; 3], String> {
    let v = parse_vec3(s)?;
    if v.iter().any(|x| *x <= 0.0) {
        return Err("every component must be positive".into());
    }
    let (lo, hi) = SPACING_LIMITS;
    if let Some(x) = v.iter().find(|x| !(lo..=hi).contains(*x)) {
        return Err(format!("{x} is outside {lo:e} to {hi:e}"));
    }
    let (min, max) = (
        v.iter().copied().fold(f64::MAX, f64::min),
        v.iter().copied().fold(0.0, f64::max),
    );
    if max / min > MAX_SPACING_RATIO {
        return Err(format!(
            "the largest spacing {max} is more than {MAX_SPACING_RATIO:e} times the smallest {min}"
        ));
    }
    Ok(v)
}

/// A direction (`--up`, `--light`, a clip plane's normal): not zero, and
/// with a length whose square `f64` holds, so that it can be normalised.
fn direction(v: [f64; 3]) -> Result<[f64; 3], String> {
    let largest = v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    if largest == 0.0 {
        return Err("a direction must not be zero".into());
    }
    if !(1e-100..=1e100).contains(&largest) {
        return Err(format!(
            "the direction {},{},{} is too short or too long to normalise (components from 1e-100 to 1e100)",
            v[0], v[1], v[2]
        ));
    }
    Ok(v)
}

pub fn parse_direction(s: &str) -> Result<[f64; 3], String> {
    direction(parse_vec3(s)?)
}

/// The fewest points per axis a volume spans (two make one cell).
const MIN_POINTS: usize = 2;

pub fn parse_dims(s: &str) -> Result<[usize; 3], String> {
    let v = numbers::<usize>(s, "point count")?;
    let dims = <[usize; 3]>::try_from(v)
        .map_err(|v| format!("expected X,Y,Z (three counts), got {}", v.len()))?;
    match dims.iter().find(|n| **n < MIN_POINTS) {
        Some(n) => Err(format!(
            "every axis needs at least {MIN_POINTS} points to span a volume, got {n}"
        )),
        None => Ok(dims),
    }
}

/// `--step`: a positive number of voxels.
pub fn parse_step(s: &str) -> Result<f64, String> {
    match parse_number(s)? {
        v if v > 0.0 => Ok(v),
        v => Err(format!("step {v} must be a positive number of voxels")),
    }
}

/// `--shininess`: the Phong exponent, finite and non-negative.
pub fn parse_shininess(s: &str) -> Result<f32, String> {
    match finite_f32(vec![parse_number(s)?])?[..] {
        [v] if v >= 0.0 => Ok(v as f32),
        ref v => Err(format!("shininess {} must be non-negative", v[0])),
    }
}

/// `--ambient-occlusion`'s radius, in voxels.
pub fn parse_ao_radius(s: &str) -> Result<f64, String> {
    let radii = volray_core::shadows::ambient::RADII;
    match parse_number(s)? {
        r if radii.contains(&r) => Ok(r),
        r => Err(format!(
            "radius {r} must be {} to {} voxels",
            radii.start(),
            radii.end()
        )),
    }
}

/// One value for all three channels, or r,g,b: reflection coefficients
/// and colours, finite and non-negative.
pub fn parse_rgb(s: &str) -> Result<[f32; 3], String> {
    let rgb = match finite_f32(numbers::<f64>(s, "number")?)?[..] {
        [v] => [v as f32; 3],
        [r, g, b] => [r as f32, g as f32, b as f32],
        ref v => {
            return Err(format!(
                "expected one value or R,G,B, got {} values",
                v.len()
            ));
        }
    };
    match rgb.iter().find(|c| **c < 0.0) {
        Some(c) => Err(format!("{c} is negative; components must be 0 or more")),
        None => Ok(rgb),
    }
}

/// `--background`: an opaque colour, components in [0, 1].
pub fn parse_background(s: &str) -> Result<[f32; 3], String> {
    let rgb = parse_rgb(s)?;
    match rgb.iter().find(|c| **c > 1.0) {
        Some(c) => Err(format!(
            "{c} is above 1; background components lie in [0, 1]"
        )),
        None => Ok(rgb),
    }
}

/// `W` (square) or `WxH`.
pub fn parse_size(s: &str) -> Result<(usize, usize), String> {
    let parse = |p: &str| {
        p.trim()
            .parse::<usize>()
            .map_err(|_| format!("'{p}' is not a pixel count"))
    };
    let (w, h) = match s.split_once(['x', 'X']) {
        Some((w, h)) => (parse(w)?, parse(h)?),
        None => (parse(s)?, parse(s)?),
    };
    if w == 0 || h == 0 {
        return Err(format!("image size {w}x{h} must be at least 1x1"));
    }
    if w.max(h) > MAX_IMAGE_SIDE {
        return Err(format!(
            "image {w}x{h}: each side must be between 1 and {MAX_IMAGE_SIDE} pixels"
        ));
    }
    if w * h > MAX_IMAGE_PIXELS {
        return Err(format!(
            "image {w}x{h} has more than {MAX_IMAGE_PIXELS} pixels"
        ));
    }
    Ok((w, h))
}

/// Workloads of `bench --cases`: volume names and window sizes.
#[derive(Debug, Clone, PartialEq)]
pub struct Cases(pub Vec<(String, usize)>);

/// `NAME:W,NAME:W,...` for `bench --cases`.
pub fn parse_cases(s: &str) -> Result<Cases, String> {
    s.split(',')
        .map(|case| {
            let (name, window) = case
                .split_once(':')
                .ok_or(format!("'{case}' is not NAME:W"))?;
            let window = window
                .trim()
                .parse::<usize>()
                .ok()
                .filter(|w| (1..=16384).contains(w))
                .ok_or(format!("'{window}' is not a window size from 1 to 16384"))?;
            let name = name.trim();
            if name.is_empty() || name.contains(['/', '\\']) {
                return Err(format!("'{name}' is not a volume name"));
            }
            Ok((name.to_string(), window))
        })
        .collect::<Result<_, _>>()
        .map(Cases)
}

/// One finite number.
fn parse_number(s: &str) -> Result<f64, String> {
    match finite(numbers::<f64>(s, "number")?)?[..] {
        [v] => Ok(v),
        ref v => Err(format!("expected one number, got {}", v.len())),
    }
}

pub fn parse_iso_value(s: &str) -> Result<f32, String> {
    let v = parse_number(s)?;
    if v.abs() > f32::MAX as f64 {
        return Err(format!("{v} is out of the range of the data's f32 values"));
    }
    Ok(v as f32)
}

pub fn parse_thickness(s: &str) -> Result<f32, String> {
    match parse_number(s)? {
        r if r > 0.0 && r <= 1e6 => Ok(r as f32),
        r => Err(format!(
            "the shell's half-width {r} must be a positive number of voxels"
        )),
    }
}

pub fn parse_gradient_opacity(s: &str) -> Result<(f32, f32), String> {
    match parse_pair(s)? {
        (lo, hi) if 0.0 <= lo && lo < hi && hi <= 1.0 => Ok((lo, hi)),
        (lo, hi) => Err(format!(
            "LO,HI = {lo},{hi} needs 0 <= LO < HI <= 1 (fractions of the largest gradient magnitude)"
        )),
    }
}

pub fn parse_fov(s: &str) -> Result<f64, String> {
    match parse_number(s)? {
        fov if fov > 0.0 && fov < 180.0 => Ok(fov),
        fov => Err(format!(
            "field of view {fov} must lie strictly between 0 and 180 degrees"
        )),
    }
}

pub fn parse_zoom(s: &str) -> Result<f64, String> {
    match parse_number(s)? {
        z if z > 0.0 => Ok(z),
        z => Err(format!("zoom {z} must be greater than 0")),
    }
}

pub fn parse_angle(s: &str) -> Result<f64, String> {
    match parse_number(s)? {
        a if a.abs() <= 1e6 => Ok(a),
        a => Err(format!("{a} degrees is not a usable angle")),
    }
}

/// `X,Y,Z,NX,NY,NZ`: a point on the plane and its normal.
pub fn parse_clip(s: &str) -> Result<([f64; 3], [f64; 3]), String> {
    match finite(numbers::<f64>(s, "number")?)?[..] {
        [_, _, _, nx, ny, nz] if nx == 0.0 && ny == 0.0 && nz == 0.0 => {
            Err("the normal NX,NY,NZ must not be zero".into())
        }
        [x, y, z, nx, ny, nz] => Ok(([x, y, z], direction([nx, ny, nz])?)),
        ref v => Err(format!(
            "expected X,Y,Z,NX,NY,NZ (a point and a normal, six numbers), got {}",
            v.len()
        )),
    }
}

/// `X0,X1,Y0,Y1,Z0,Z1` as the box's (low, high) corners.
pub fn parse_crop(s: &str) -> Result<([f64; 3], [f64; 3]), String> {
    let v = finite(numbers::<f64>(s, "number")?)?;
    if v.len() != 6 {
        return Err(format!(
            "expected X0,X1,Y0,Y1,Z0,Z1 (six numbers), got {}",
            v.len()
        ));
    }
    for (axis, name) in ["X", "Y", "Z"].iter().enumerate() {
        let (lo, hi) = (v[2 * axis], v[2 * axis + 1]);
        if lo >= hi {
            return Err(format!("{name}0 {lo} must be below {name}1 {hi}"));
        }
    }
    Ok(([v[0], v[2], v[4]], [v[1], v[3], v[5]]))
}

pub fn parse_fps(s: &str) -> Result<f64, String> {
    match parse_number(s)? {
        f if f > 0.0 && f <= 100.0 => Ok(f),
        f => Err(format!("{f} frames per second must be in (0, 100]")),
    }
}

pub fn parse_bit_depth(s: &str) -> Result<u8, String> {
    match s {
        "8" => Ok(8),
        "16" => Ok(16),
        _ => Err(format!("bit depth must be 8 or 16, got '{s}'")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_parsers() {
        assert_eq!(parse_vec3("1, -2.5,3e2"), Ok([1.0, -2.5, 300.0]));
        assert!(parse_vec3("1,2").is_err());
        assert!(parse_vec3("1,nan,2").is_err());
        assert_eq!(parse_rgb("0.5"), Ok([0.5; 3]));
        assert_eq!(parse_rgb("1,0,0.25"), Ok([1.0, 0.0, 0.25]));
        assert!(parse_rgb("1,0").is_err());
        assert_eq!(parse_size("480"), Ok((480, 480)));
        assert_eq!(parse_size("640x360"), Ok((640, 360)));
        assert!(parse_size("0").is_err());
        assert!(parse_size("12x").is_err());
        assert_eq!(parse_dims("4,5,6"), Ok([4, 5, 6]));
        assert!(parse_dims("4,-5,6").is_err());
        assert_eq!(parse_pair("0.1,0.9"), Ok((0.1, 0.9)));
        assert!(parse_spacing("1,0,1").is_err());
        assert_eq!(parse_bit_depth("16"), Ok(16));
        assert_eq!(
            parse_cases("fractal_129:480, hydrogen_421:120"),
            Ok(Cases(vec![
                ("fractal_129".to_string(), 480),
                ("hydrogen_421".to_string(), 120)
            ]))
        );
        assert!(parse_cases("fractal_129").is_err());
        assert!(parse_cases("fractal_129:0").is_err());
        assert!(parse_cases("../x:10").is_err());
        assert!(parse_bit_depth("12").is_err());
    }

    #[test]
    fn rendering_option_parsers() {
        assert_eq!(parse_fov("30"), Ok(30.0));
        for bad in ["0", "180", "-5", "nan", "30,40"] {
            assert!(parse_fov(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_zoom("2"), Ok(2.0));
        assert!(parse_zoom("0").is_err() && parse_zoom("-1").is_err());
        assert_eq!(parse_angle("-90"), Ok(-90.0));
        assert!(parse_angle("inf").is_err());
        assert_eq!(parse_thickness("0.5"), Ok(0.5));
        assert!(parse_thickness("0").is_err());
        assert_eq!(parse_iso_value("-3e2"), Ok(-300.0));
        assert!(parse_iso_value("1e300").is_err());
        assert_eq!(parse_gradient_opacity("0,0.5"), Ok((0.0, 0.5)));
        assert!(parse_gradient_opacity("0.5,0.5").is_err());
        assert!(parse_gradient_opacity("0.1,1.5").is_err());
        assert_eq!(
            parse_clip("1,2,3,0,-1,0"),
            Ok(([1.0, 2.0, 3.0], [0.0, -1.0, 0.0]))
        );
        assert!(parse_clip("1,2,3,0,0,0").is_err());
        assert!(parse_clip("1,2,3,0,1").is_err());
        // X0,X1,Y0,Y1,Z0,Z1 → (low corner, high corner).
        assert_eq!(
            parse_crop("-1,1,0,2,-3,-2"),
            Ok(([-1.0, 0.0, -3.0], [1.0, 2.0, -2.0]))
        );
        assert!(parse_crop("1,-1,0,2,-3,-2").is_err());
        assert!(parse_crop("0,1,0,1,2,2").is_err());
        assert!(parse_crop("0,1,0,1").is_err());
        assert_eq!(parse_fps("24"), Ok(24.0));
        assert!(parse_fps("0").is_err() && parse_fps("101").is_err());
    }
}

/// `--label-opacity L:A,...`: labels (integers) and opacities in [0, 1].
#[derive(Debug, Clone, PartialEq)]
pub struct LabelOpacities(pub Vec<(i64, f32)>);

pub fn parse_label_opacity(s: &str) -> Result<LabelOpacities, String> {
    let pairs = s.split(',').map(|pair| {
        let (l, a) = pair
            .split_once(':')
            .ok_or_else(|| format!("'{pair}' is not L:A (a label and its opacity)"))?;
        let label = parse_label(l)?;
        let a = parse_number(a.trim())?;
        if !(0.0..=1.0).contains(&a) {
            return Err(format!("opacity {a} of label {label} must be in [0, 1]"));
        }
        Ok((label, a as f32))
    });
    pairs
        .collect::<Result<Vec<_>, String>>()
        .map(LabelOpacities)
}

/// `--show-labels L,...`: labels (integers).
#[derive(Debug, Clone, PartialEq)]
pub struct LabelList(pub Vec<i64>);

pub fn parse_label_list(s: &str) -> Result<LabelList, String> {
    s.split(',')
        .map(parse_label)
        .collect::<Result<Vec<_>, String>>()
        .map(LabelList)
}

/// One label: an integer.
fn parse_label(s: &str) -> Result<i64, String> {
    s.trim()
        .parse::<i64>()
        .map_err(|_| format!("label '{}' is not an integer", s.trim()))
}
