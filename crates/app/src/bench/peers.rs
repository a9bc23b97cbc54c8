//! `volray bench --peers DIR`: the peer benchmark's six workloads, rendered
//! exactly as the peers' harness (`../shared/peers`, `common.py`) defines
//! them, so that volray's times compare with VTK's and yt's.
//!
//! The workload, from the peers' README:
//! - volumes: `DIR/<name>.raw`, float32 little-endian, x fastest, with a
//!   JSON sidecar `DIR/<name>.json` giving `dims`, `min`, `max` (and
//!   `spacing`, `origin`); volray also reads a `dtype` of `int16`,
//!   `uint16`, `int8` or `uint8` there, kept in that type (the large-volume
//!   benchmark's CT phantom, `scripts/make_ct_phantom.py --sidecar`, timed
//!   against VTK by `scripts/vtk_typed_bench.py`);
//! - view: orthographic along +x through the volume's centre, +z up (so
//!   screen right is −y), the window fitting the y-z extent exactly;
//! - sampling: 0.5 voxel, trilinear, front-to-back compositing;
//! - transfer functions of `t = (v − min)/(max − min)`: opacity per voxel
//!   through (0, 0), (0.05, 0), (0.95, 0.95), (1, 0.95), corrected to
//!   `1 − (1 − a)^0.5` per sample; colour linear through (0.230, 0.299,
//!   0.754), (0.865, 0.865, 0.865) at 0.5 and (0.706, 0.016, 0.150) at 1;
//! - shading: one white headlight, ambient 0.1, diffuse 0.7, specular 0.2,
//!   power 10; black background;
//! - timing: one warm-up, then 5 timed frames, the median reported;
//!   samples/s is nominal, `W²·(n − 1)/0.5` per frame over the median.

use super::vtk::Harness;
use super::{JsonRow, Timed, input, io, median, ms, time_frames};
use crate::AppError;
use std::path::Path;
use volray_core::PiecewiseLinear;
use volray_core::glam::DVec3;
use volray_core::{Camera, Phong, RenderSettings, Renderer, TransferFunction, Volume};
use volray_io::{DType, Endian, RawOptions};

/// The workloads: dataset and window (pixels per side), as in `common.py`.
pub const CASES: [(&str, usize); 6] = [
    ("hydrogen_421", 120),
    ("hydrogen_632", 120),
    ("fractal_65", 240),
    ("fractal_129", 480),
    ("fractal_257", 480),
    ("fractal_257", 1024),
];

/// Gives `out` a line, formatted as `format!` does.
macro_rules! outln {
    ($out:expr, $($arg:tt)*) => {
        $out(format!($($arg)*))
    };
}

/// The sample step, in voxels.
pub const STEP: f64 = 0.5;
/// Opacity per unit voxel distance at `t`.
const OPACITY: [(f32, f32); 4] = [(0.0, 0.0), (0.05, 0.0), (0.95, 0.95), (1.0, 0.95)];
/// Colour at `t`.
const COLOR: [(f32, [f32; 3]); 3] = [
    (0.0, [0.230, 0.299, 0.754]),
    (0.5, [0.865, 0.865, 0.865]),
    (1.0, [0.706, 0.016, 0.150]),
];

/// What a sidecar says about its volume.
struct Sidecar {
    dims: [usize; 3],
    dtype: DType,
    min: f64,
    max: f64,
    spacing: [f64; 3],
    origin: [f64; 3],
}

/// Reads `DIR/<name>.json` and the raw volume it describes.
fn load(dir: &Path, name: &str) -> Result<(Volume, Sidecar), AppError> {
    let path = dir.join(format!("{name}.json"));
    let text = std::fs::read_to_string(&path).map_err(|e| {
        io(format!(
            "{}: cannot read the sidecar: {e} (make the volumes with the peers' make_volumes.py)",
            path.display()
        ))
    })?;
    let side = parse_sidecar(&text).map_err(|e| input(format!("{}: {e}", path.display())))?;
    let mut raw = RawOptions::new(side.dims, side.dtype);
    raw.endian = Endian::Little;
    raw.spacing = DVec3::from(side.spacing);
    let raw_path = dir.join(format!("{name}.raw"));
    let volume = volray_io::read_volume(&raw_path, Some(&raw))?
        .with_origin(DVec3::from(side.origin))
        .map_err(|e| input(format!("{}: {e}", path.display())))?;
    Ok((volume, side))
}

fn parse_sidecar(text: &str) -> Result<Sidecar, String> {
    let json: serde_json::Value =
        serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
    let field = |key: &str| json.get(key).ok_or(format!("no \"{key}\""));
    let number = |key: &str| {
        field(key)?
            .as_f64()
            .filter(|v| v.is_finite())
            .ok_or(format!("\"{key}\" is not a finite number"))
    };
    let triple = |key: &str, default: [f64; 3]| -> Result<[f64; 3], String> {
        match json.get(key) {
            None => Ok(default),
            Some(v) => v
                .as_array()
                .filter(|a| a.len() == 3)
                .and_then(|a| {
                    let v: Option<Vec<f64>> = a.iter().map(|x| x.as_f64()).collect();
                    v.and_then(|v| <[f64; 3]>::try_from(v).ok())
                })
                .ok_or(format!("\"{key}\" is not three numbers")),
        }
    };
    if let Some(v) = json.get("byte_order")
        && v.as_str() != Some("little")
    {
        return Err(format!("\"byte_order\" is {v}, expected \"little\""));
    }
    // NumPy's names.
    let dtype = match json.get("dtype").map(|v| v.as_str()) {
        None | Some(Some("float32")) => DType::F32,
        Some(Some("int16")) => DType::I16,
        Some(Some("uint16")) => DType::U16,
        Some(Some("int8")) => DType::I8,
        Some(Some("uint8")) => DType::U8,
        Some(_) => {
            return Err(format!(
                "\"dtype\" is {}, expected \"float32\", \"int16\", \"uint16\", \"int8\" or \"uint8\"",
                json["dtype"]
            ));
        }
    };
    let dims = triple("dims", [0.0; 3])?;
    if dims
        .iter()
        .any(|d| d.fract() != 0.0 || *d < 2.0 || *d > 1e5)
    {
        return Err(format!(
            "\"dims\" {dims:?} must be three whole numbers from 2"
        ));
    }
    let (min, max) = (number("min")?, number("max")?);
    if min >= max {
        return Err(format!("\"min\" {min} must be below \"max\" {max}"));
    }
    Ok(Sidecar {
        dims: dims.map(|d| d as usize),
        dtype,
        min,
        max,
        spacing: triple("spacing", [1.0; 3])?,
        origin: triple("origin", [0.0; 3])?,
    })
}

/// The peers' transfer functions over `[min, max]`.
fn transfer_function(min: f64, max: f64) -> TransferFunction {
    let opacity = OPACITY.iter().map(|&(t, a)| (t, [a])).collect();
    TransferFunction {
        domain: Some((min, max)),
        opacity: Some(PiecewiseLinear::new("opacity", opacity).expect("valid points")),
        color: Some(PiecewiseLinear::new("color", COLOR.to_vec()).expect("valid points")),
    }
}

/// The peers' settings for `volume` (value range `[min, max]`) in a
/// `window²` image.
fn workload(volume: &Volume, (min, max): (f64, f64), window: usize) -> RenderSettings {
    let centre = volume.centre();
    RenderSettings {
        width: window,
        height: window,
        camera: Camera {
            // Orthographic: only the direction matters, along +x.
            view_point: Some(centre - DVec3::X * (1.0 + 2.0 * volume.extent().x)),
            look_at: Some(centre),
            up: DVec3::Z,
            ..Camera::default()
        },
        step: STEP,
        transfer_function: transfer_function(min, max),
        phong: Phong {
            ambient: [0.1; 3],
            diffuse: [0.7; 3],
            specular: [0.2; 3],
            shininess: 10.0,
            light_color: [1.0; 3],
        },
        shading: true,
        light_direction: None,
        background: [0.0; 3],
        ..RenderSettings::default()
    }
}

/// One workload's result.
struct Row {
    dataset: String,
    dims: [usize; 3],
    window: usize,
    median_s: f64,
    /// Medians of the parts of the timed frames, ms: binning, and lighting
    /// with casting.
    parts: [f64; 2],
    classify_ms: f64,
    bricks: usize,
    /// The median number of bricks a timed frame lit.
    lit: f64,
    vtk: Option<super::vtk::VtkRun>,
}

/// What `volray bench --peers DIR` times, as its flags say.
pub struct Peers<'a> {
    /// DIR: the peers' volumes and their sidecars.
    pub dir: &'a Path,
    /// The workloads (dataset, window); `None` for all of [`CASES`].
    pub cases: Option<Vec<(String, usize)>>,
    /// Timed frames after the warm-up.
    pub frames: u32,
    /// The look's shadows and ambient occlusion, over the peers' shading.
    pub shadows: bool,
    pub ambient_occlusion: Option<f64>,
    /// VTK timed on each workload too (`--vs-vtk`), by this Python (else
    /// the peers' venv's).
    pub vs_vtk: bool,
    pub python: Option<&'a Path>,
}

/// Times each workload of `args` on `pool`, VTK first where asked,
/// giving `out` each line of the report (a heading, a line a workload, the
/// closing table) as it comes; returns the `--json` rows.
pub fn run(
    args: &Peers<'_>,
    pool: &rayon::ThreadPool,
    out: &mut dyn FnMut(String),
) -> Result<Vec<JsonRow>, AppError> {
    let dir = args.dir;
    let threads = pool.current_num_threads();
    let harness = if args.vs_vtk {
        Some(Harness::find(dir, args.python)?)
    } else {
        None
    };
    let cases: Vec<(String, usize)> = match &args.cases {
        Some(cases) => cases.clone(),
        None => CASES.iter().map(|(d, w)| (d.to_string(), *w)).collect(),
    };
    outln!(
        out,
        "volray bench --peers {}: {} workloads, {threads} threads, 1 warm-up + {} timed frames each, turned 0.5° apart",
        dir.display(),
        cases.len(),
        args.frames
    );
    let mut rows = Vec::new();
    for (dataset, window) in cases {
        let dataset = dataset.as_str();
        let (volume, side) = load(dir, dataset)?;
        let settings = RenderSettings {
            shadows: args.shadows,
            ambient_occlusion: args.ambient_occlusion,
            ..workload(&volume, (side.min, side.max), window)
        };
        let fail = |e: volray_core::RenderError| input(format!("{dataset}: {e}"));
        // VTK first, then volray: each sees the machine as the other left it.
        let vtk = match &harness {
            Some(h) => Some(h.run(dataset, window, threads, args.frames)?),
            None => None,
        };
        let mut classify_ms = 0.0;
        let (warm, timed) = pool.install(|| {
            let renderer = Renderer::new(&volume).map_err(fail)?;
            time_frames(&renderer, &settings, args.frames, |frame, t| {
                if frame == 0 {
                    classify_ms = t.parts.map_or(0.0, |p| ms(p.classify));
                }
            })
            .map_err(fail)
        })?;
        let part = |pick: fn(&volray_core::FrameTimes) -> f64| {
            median(
                timed
                    .iter()
                    .filter_map(|t: &Timed| t.parts.as_ref().map(pick))
                    .collect(),
            )
        };
        let row = Row {
            dataset: dataset.to_string(),
            dims: volume.dims(),
            window,
            median_s: median(timed.iter().map(|t| t.wall).collect()),
            parts: [part(|p| ms(p.bin)), part(|p| ms(p.cast))],
            classify_ms,
            bricks: timed
                .first()
                .and_then(|t| t.parts.map(|p| p.bricks))
                .unwrap_or(0),
            lit: part(|p| p.lit as f64),
            vtk: match (&harness, vtk) {
                (Some(h), Some(run)) => Some(h.compare(run, &warm, dataset, window)?),
                _ => None,
            },
        };
        print_row(out, &row, threads);
        rows.push(row);
    }
    print_table(out, &rows, threads);
    Ok(rows
        .iter()
        .map(|r| JsonRow {
            dataset: r.dataset.clone(),
            window: r.window,
            threads,
            median_s: r.median_s,
            vtk_median_s: r.vtk.as_ref().map(|v| v.median_s),
        })
        .collect())
}

/// Nominal samples per frame: `W²` rays of `(n − 1)/step` samples (point
/// data, as the peers count them for VTK).
fn nominal(row: &Row) -> f64 {
    (row.window * row.window) as f64 * (row.dims[0] - 1) as f64 / STEP
}

fn print_row(out: &mut dyn FnMut(String), row: &Row, threads: usize) {
    let [bin, cast] = row.parts;
    let head = format!(
        "  {:<13} {:>5}² t={threads}: median {:.4} s, {:.3e} samples/s (bin {bin:.2} + shade and cast {cast:.2} ms; {} bricks, {} lit a frame, classified once in {:.1} ms)",
        row.dataset,
        row.window,
        row.median_s,
        nominal(row) / row.median_s,
        row.bricks,
        row.lit,
        row.classify_ms,
    );
    match &row.vtk {
        Some(v) => outln!(
            out,
            "{head}; VTK {:.4} s: VTK/volray {:.2}x",
            v.median_s,
            v.median_s / row.median_s
        ),
        None => outln!(out, "{head}"),
    }
}

/// The closing table, in Markdown.
fn print_table(out: &mut dyn FnMut(String), rows: &[Row], threads: usize) {
    outln!(out, "");
    let vtk = rows.iter().any(|r| r.vtk.is_some());
    if vtk {
        outln!(
            out,
            "| dataset, window | volray median s | samples/s (nominal) | VTK fixed-point median s | VTK / volray | image vs VTK: mean abs diff (levels of 255) |"
        );
        outln!(out, "|---|---|---|---|---|---|");
    } else {
        outln!(
            out,
            "| dataset, window | volray median s | samples/s (nominal) |"
        );
        outln!(out, "|---|---|---|");
    }
    for r in rows {
        let name = format!(
            "{} {}^3, {}^2 ({threads} thread{})",
            r.dataset,
            r.dims[0],
            r.window,
            if threads == 1 { "" } else { "s" }
        );
        let volray = format!("{:.4} | {:.3e}", r.median_s, nominal(r) / r.median_s);
        match &r.vtk {
            Some(v) => outln!(
                out,
                "| {name} | {volray} | {:.4} | {:.2} | {:.2} (means {:.1} vs {:.1}) |",
                v.median_s,
                v.median_s / r.median_s,
                v.mean_abs_diff,
                v.mean_volray,
                v.mean_vtk
            ),
            None => outln!(out, "| {name} | {volray} |"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sidecars_are_read_and_checked() {
        let ok = parse_sidecar(
            r#"{"dims": [50, 50, 50], "dtype": "float32", "byte_order": "little",
                "min": 0.5, "max": 2.0, "spacing": [1.0, 1.0, 2.0]}"#,
        )
        .unwrap();
        assert_eq!(ok.dims, [50, 50, 50]);
        assert_eq!(ok.dtype, DType::F32);
        assert_eq!((ok.min, ok.max), (0.5, 2.0));
        let ct =
            parse_sidecar(r#"{"dims": [8, 8, 8], "dtype": "int16", "min": -1000, "max": 1500}"#);
        assert_eq!(ct.unwrap().dtype, DType::I16);
        assert_eq!(ok.spacing, [1.0, 1.0, 2.0]);
        assert_eq!(ok.origin, [0.0; 3]);
        for (text, want) in [
            (r#"{"dims": [50, 50], "min": 0, "max": 1}"#, "\"dims\""),
            (r#"{"dims": [50, 50, 1], "min": 0, "max": 1}"#, "\"dims\""),
            (r#"{"dims": [5, 5, 5], "min": 1, "max": 1}"#, "below"),
            (r#"{"dims": [5, 5, 5], "max": 1}"#, "no \"min\""),
            (
                r#"{"dims": [5, 5, 5], "min": 0, "max": 1, "dtype": "float64"}"#,
                "float32",
            ),
            (
                r#"{"dims": [5, 5, 5], "min": 0, "max": 1, "byte_order": "big"}"#,
                "little",
            ),
            ("[1,", "not JSON"),
        ] {
            let err = parse_sidecar(text).err().unwrap();
            assert!(err.contains(want), "{text}: {err}");
        }
    }

    #[test]
    fn the_workload_is_the_peers() {
        let v = Volume::new([65, 65, 65], vec![0.0; 65 * 65 * 65]).unwrap();
        let s = workload(&v, (0.0, 2.0), 240);
        let view =
            volray_core::camera::OrthographicView::frame(&s.camera, v.bounds(), 240, 240).unwrap();
        // Along +x, screen right −y, up +z; the window is the y-z face.
        assert_eq!(view.direction, DVec3::X);
        assert!((view.right + DVec3::Y).length() < 1e-12);
        assert!((view.pixel_size - 64.0 / 240.0).abs() < 1e-12);
        let tf = &s.transfer_function;
        assert_eq!(tf.opacity.as_ref().unwrap().eval(0.5), [0.475]);
        assert!((tf.color.as_ref().unwrap().eval(0.25)[0] - 0.5475).abs() < 1e-6);
        assert_eq!((s.step, s.background), (0.5, [0.0; 3]));
        assert_eq!(s.light_direction, None);
    }
}
