//! Where a NRRD file's samples lie: the named spaces, `space directions`
//! and `space origin`, or `spacings`, `axis mins`/`axis maxs` and
//! `centers` without a space; which axis of a 4-D file holds the volumes;
//! and the length unit.

use std::path::Path;

use volray_core::glam::DVec3;

use super::header::Header;
use super::values::{quoted, vectors};
use crate::error::IoError;
use crate::shared::text_header::Field;
use crate::shared::units::{AxisUnit, one_length_unit};

/// Axis kinds that describe positions in space (`???` and `none` say
/// nothing and count as spatial).
const SPATIAL_KINDS: [&str; 4] = ["domain", "space", "???", "none"];

/// Whether an axis of kind `kind` holds the components of one value
/// (a vector, a colour, a list of measurements): every kind the format
/// defines but the spatial ones, `time`, and `stub` and `scalar` (one
/// sample long).
pub(crate) fn holds_channels(kind: &str) -> bool {
    let not = ["time", "stub", "scalar"];
    !(SPATIAL_KINDS.iter().chain(&not)).any(|k| k.eq_ignore_ascii_case(kind))
}

/// Every kind the format defines, for checking `kinds`.
const KINDS: [&str; 33] = [
    "domain",
    "space",
    "time",
    "list",
    "point",
    "vector",
    "covariant-vector",
    "normal",
    "stub",
    "scalar",
    "complex",
    "2-vector",
    "3-color",
    "RGB-color",
    "HSV-color",
    "XYZ-color",
    "4-color",
    "RGBA-color",
    "3-vector",
    "3-gradient",
    "3-normal",
    "4-vector",
    "quaternion",
    "2D-symmetric-matrix",
    "2D-masked-symmetric-matrix",
    "2D-matrix",
    "2D-masked-matrix",
    "3D-symmetric-matrix",
    "3D-masked-symmetric-matrix",
    "3D-matrix",
    "3D-masked-matrix",
    "???",
    "none",
];

/// A named NRRD space.
struct Space {
    name: &'static str,
    dim: usize,
    time: bool,
    /// How the space's axes read, for the note.
    axes: &'static str,
    left_handed: bool,
}

fn parse_space(path: &Path, name: &str) -> Result<Space, IoError> {
    let space = |name, dim, time, axes, left_handed| Space {
        name,
        dim,
        time,
        axes,
        left_handed,
    };
    Ok(match name.trim().to_ascii_lowercase().as_str() {
        "right-anterior-superior" | "ras" => space(
            "right-anterior-superior",
            3,
            false,
            "+x right, +y anterior, +z superior",
            false,
        ),
        "left-anterior-superior" | "las" => space(
            "left-anterior-superior",
            3,
            false,
            "+x left, +y anterior, +z superior",
            true,
        ),
        "left-posterior-superior" | "lps" => space(
            "left-posterior-superior",
            3,
            false,
            "+x left, +y posterior, +z superior",
            false,
        ),
        "right-anterior-superior-time" | "rast" => space(
            "right-anterior-superior-time",
            4,
            true,
            "+x right, +y anterior, +z superior",
            false,
        ),
        "left-anterior-superior-time" | "last" => space(
            "left-anterior-superior-time",
            4,
            true,
            "+x left, +y anterior, +z superior",
            true,
        ),
        "left-posterior-superior-time" | "lpst" => space(
            "left-posterior-superior-time",
            4,
            true,
            "+x left, +y posterior, +z superior",
            false,
        ),
        "scanner-xyz" => space("scanner-xyz", 3, false, "the scanner's x, y, z", false),
        "scanner-xyz-time" => space("scanner-xyz-time", 4, true, "the scanner's x, y, z", false),
        "3d-right-handed" => space("3D-right-handed", 3, false, "a right-handed x, y, z", false),
        "3d-left-handed" => space("3D-left-handed", 3, false, "a left-handed x, y, z", true),
        "3d-right-handed-time" => space(
            "3D-right-handed-time",
            4,
            true,
            "a right-handed x, y, z",
            false,
        ),
        "3d-left-handed-time" => space(
            "3D-left-handed-time",
            4,
            true,
            "a left-handed x, y, z",
            true,
        ),
        _ => {
            return Err(Field::nrrd(path, "space").error(format!("unknown space \"{name}\"")));
        }
    })
}

/// Where the samples lie, from the header's geometry fields.
pub(super) struct Geometry {
    /// The axis holding several volumes, in a 4-D file.
    pub frame_axis: Option<usize>,
    /// The three axes of the volume, in file order.
    pub axes: [usize; 3],
    /// World step per volume axis, and the first sample's position.
    pub steps: [DVec3; 3],
    pub origin: DVec3,
    pub unit: Option<String>,
    pub kinds: Option<Vec<String>>,
}

impl Geometry {
    /// The geometry of a 2-D image (`dimension: 2`): `space directions`
    /// (of a 2-D or 3-D space) or `spacings`, and `space origin`; the
    /// third axis is a unit step along z.
    pub(super) fn image(path: &Path, header: &Header) -> Result<Geometry, IoError> {
        let space_dim = match (header.get("space dimension"), header.get("space")) {
            (Some(v), _) => Some(Field::nrrd(path, "space dimension").uint(v)?),
            (None, Some(s)) => Some(parse_space(path, s)?.dim),
            (None, None) => None,
        };
        let sd = space_dim.unwrap_or(3);
        if !(2..=3).contains(&sd) {
            return Err(Field::nrrd(path, "space dimension")
                .error(format!("{sd}: a 2-D image lies in a 2-D or 3-D space")));
        }
        let point = |c: &[f64]| DVec3::new(c[0], c[1], c.get(2).copied().unwrap_or(0.0));
        let mut steps = [DVec3::X, DVec3::Y, DVec3::Z];
        if let Some(v) = header.get("space directions") {
            for (a, d) in vectors(path, "space directions", v, 2, sd)?
                .iter()
                .enumerate()
            {
                if let Some(c) = d {
                    steps[a] = point(c);
                }
            }
        } else if let Some(v) = header.get("spacings") {
            let spacings = Field::nrrd(path, "spacings").numbers(v, 2)?;
            for a in 0..2 {
                if spacings[a].is_finite() && spacings[a] != 0.0 {
                    steps[a] *= spacings[a];
                }
            }
        }
        let origin = match header.get("space origin") {
            Some(v) => match &vectors(path, "space origin", v, 1, sd)?[0] {
                Some(c) => point(c),
                None => DVec3::ZERO,
            },
            None => DVec3::ZERO,
        };
        Ok(Geometry {
            frame_axis: None,
            axes: [0, 1, 2],
            steps,
            origin,
            unit: None,
            kinds: None,
        })
    }

    pub(super) fn parse(
        path: &Path,
        header: &Header,
        sizes: &[usize],
        notes: &mut Vec<String>,
    ) -> Result<Geometry, IoError> {
        let dim = sizes.len();
        let bad = |field, why: String| Field::nrrd(path, field).error(why);

        let space = header
            .get("space")
            .map(|s| parse_space(path, s))
            .transpose()?;
        let space_dim = match (header.get("space dimension"), &space) {
            (Some(v), Some(s)) => {
                let d = Field::nrrd(path, "space dimension").uint(v)?;
                if d != s.dim {
                    return Err(bad(
                        "space dimension",
                        format!("{d}, but space {} has {} dimensions", s.name, s.dim),
                    ));
                }
                Some(d)
            }
            (Some(v), None) => Some(Field::nrrd(path, "space dimension").uint(v)?),
            (None, Some(s)) => Some(s.dim),
            (None, None) => None,
        };
        let time_space = space.as_ref().is_some_and(|s| s.time);
        if let Some(sd) = space_dim
            && sd != 3
            && !(sd == 4 && time_space)
        {
            return Err(bad(
                "space dimension",
                format!(
                    "{sd}: volray places volumes in 3-D space (or the spatial part of a named -time space)"
                ),
            ));
        }

        let kinds = match header.get("kinds") {
            Some(v) => {
                let k: Vec<String> = Field::nrrd(path, "kinds")
                    .words(v, dim)?
                    .iter()
                    .map(|s| s.to_string())
                    .collect();
                if let Some(unknown) = k
                    .iter()
                    .find(|k| !KINDS.iter().any(|known| known.eq_ignore_ascii_case(k)))
                {
                    return Err(bad("kinds", format!("unknown kind \"{unknown}\"")));
                }
                Some(k)
            }
            None => None,
        };
        let is_spatial_kind = |k: &str| SPATIAL_KINDS.iter().any(|s| s.eq_ignore_ascii_case(k));

        // Spatial parts of the space directions; `None` for a `none` axis
        // or a pure time direction.
        let directions: Option<Vec<Option<DVec3>>> = match header.get("space directions") {
            Some(v) => {
                let sd = space_dim.ok_or_else(|| {
                    bad(
                        "space directions",
                        "given without \"space\" or \"space dimension\"".to_string(),
                    )
                })?;
                let raw = vectors(path, "space directions", v, dim, sd)?;
                let mut dirs = Vec::with_capacity(dim);
                for (a, d) in raw.iter().enumerate() {
                    dirs.push(match d {
                        None => None,
                        Some(c) if sd == 4 && c[..3].iter().all(|&x| x == 0.0) => None,
                        Some(c) if sd == 4 && c[3] != 0.0 => {
                            return Err(bad(
                                "space directions",
                                format!("axis {a} steps through both space and time"),
                            ));
                        }
                        Some(c) => Some(DVec3::new(c[0], c[1], c[2])),
                    });
                }
                Some(dirs)
            }
            None => None,
        };

        let frame_axis = if dim == 3 {
            if let Some(a) = directions
                .as_ref()
                .and_then(|d| d.iter().position(Option::is_none))
            {
                return Err(bad(
                    "space directions",
                    format!(
                        "axis {a} has no spatial direction, but a 3-D file needs three spatial axes"
                    ),
                ));
            }
            if let Some(k) = &kinds
                && let Some(a) = k
                    .iter()
                    .position(|k| !is_spatial_kind(k) && !k.eq_ignore_ascii_case("time"))
            {
                return Err(bad(
                    "kinds",
                    format!(
                        "axis {a} has kind {}, but a 3-D file needs three spatial axes",
                        k[a]
                    ),
                ));
            }
            None
        } else if let Some(d) = &directions {
            let non: Vec<usize> = (0..dim).filter(|&a| d[a].is_none()).collect();
            if non.len() != 1 {
                return Err(bad(
                    "space directions",
                    format!(
                        "{} axes have no spatial direction, but a 4-D file needs exactly one (the axis of volumes)",
                        non.len()
                    ),
                ));
            }
            Some(non[0])
        } else if let Some(k) = &kinds {
            let non: Vec<usize> = (0..dim).filter(|&a| !is_spatial_kind(&k[a])).collect();
            match non.len() {
                1 => Some(non[0]),
                0 => {
                    notes.push(
                        "4-D file with all axes spatial kinds: the last axis is taken as the axis of volumes".to_string(),
                    );
                    Some(dim - 1)
                }
                n => {
                    return Err(bad(
                        "kinds",
                        format!(
                            "{n} axes are not spatial, but a 4-D file needs exactly one (the axis of volumes)"
                        ),
                    ));
                }
            }
        } else {
            notes.push("4-D file without kinds or space directions: the last axis is taken as the axis of volumes".to_string());
            Some(dim - 1)
        };
        let mut axes = [0; 3];
        for (i, a) in (0..dim).filter(|&a| Some(a) != frame_axis).enumerate() {
            axes[i] = a;
        }

        let spacings = header
            .get("spacings")
            .map(|v| Field::nrrd(path, "spacings").numbers(v, dim))
            .transpose()?;
        let mins = header
            .get("axis mins")
            .map(|v| Field::nrrd(path, "axis mins").numbers(v, dim))
            .transpose()?;
        let maxs = header
            .get("axis maxs")
            .map(|v| Field::nrrd(path, "axis maxs").numbers(v, dim))
            .transpose()?;
        // NaN is NRRD's "not known" (the spacing then defaults); an
        // infinite spacing or bound is no value at all.
        for (field, values) in [
            ("spacings", &spacings),
            ("axis mins", &mins),
            ("axis maxs", &maxs),
        ] {
            if let Some(v) = values.iter().flatten().find(|v| v.is_infinite()) {
                return Err(IoError::invalid(
                    path,
                    format!(
                        "NRRD field \"{field}\": {v} is not a finite number (nan means not known)"
                    ),
                ));
            }
        }
        let centers = match header.get("centers") {
            Some(v) => {
                let c: Vec<String> = Field::nrrd(path, "centers")
                    .words(v, dim)?
                    .iter()
                    .map(|s| s.to_ascii_lowercase())
                    .collect();
                if let Some(u) = c
                    .iter()
                    .find(|c| !matches!(c.as_str(), "cell" | "node" | "???" | "none"))
                {
                    return Err(bad(
                        "centers",
                        format!("unknown centering \"{u}\" (cell or node)"),
                    ));
                }
                Some(c)
            }
            None => None,
        };

        let mut steps = [DVec3::ZERO; 3];
        let mut origin = DVec3::ZERO;
        if let Some(dirs) = &directions {
            for (i, &a) in axes.iter().enumerate() {
                steps[i] = dirs[a].unwrap_or(DVec3::ZERO);
            }
            if spacings
                .as_ref()
                .is_some_and(|s| axes.iter().any(|&a| s[a].is_finite()))
            {
                notes.push("\"spacings\" ignored: \"space directions\" give the grid".to_string());
            }
            match header.get("space origin") {
                Some(v) => {
                    let sd = space_dim.unwrap_or(3);
                    let o = vectors(path, "space origin", v, 1, sd)?;
                    match &o[0] {
                        Some(c) if c[..3].iter().all(|x| x.is_finite()) => {
                            origin = DVec3::new(c[0], c[1], c[2]);
                        }
                        _ => notes.push(
                            "\"space origin\" is none: the first sample is placed at 0".to_string(),
                        ),
                    }
                }
                None => {
                    notes.push("no \"space origin\": the first sample is placed at 0".to_string())
                }
            }
        } else {
            let mut defaulted_centre = false;
            for (i, &a) in axes.iter().enumerate() {
                let n = sizes[a] as f64;
                let centre = centers.as_ref().map_or("???", |c| c[a].as_str());
                let cell = centre != "node";
                let min = mins.as_ref().map_or(f64::NAN, |m| m[a]);
                let max = maxs.as_ref().map_or(f64::NAN, |m| m[a]);
                let given = spacings.as_ref().map_or(f64::NAN, |s| s[a]);
                let spacing = if given.is_finite() {
                    given
                } else if min.is_finite() && max.is_finite() {
                    let cells = if cell { n } else { n - 1.0 };
                    notes.push(format!(
                        "axis {a}: spacing {} from \"axis mins\" and \"axis maxs\" ({} centering)",
                        (max - min) / cells,
                        if cell { "cell" } else { "node" }
                    ));
                    (max - min) / cells
                } else {
                    if spacings.is_some() {
                        notes.push(format!("axis {a}: spacing not given (nan): 1 used"));
                    }
                    1.0
                };
                steps[i][i] = spacing;
                if min.is_finite() {
                    if cell {
                        origin[i] = min + spacing / 2.0;
                        defaulted_centre |= centre != "cell";
                    } else {
                        origin[i] = min;
                    }
                }
            }
            if defaulted_centre {
                notes.push(
                    "\"axis mins\" without \"centers\": samples taken as cell-centred, the first half a spacing inside the minimum (as teem and ITK do)".to_string(),
                );
            }
        }

        if let Some(s) = &space {
            notes.push(if s.left_handed {
                format!(
                    "positions are in the file's {} space ({}), kept as written; it is left-handed, so the rendering is a mirror image",
                    s.name, s.axes
                )
            } else {
                format!(
                    "positions are in the file's {} space ({}), kept as written",
                    s.name, s.axes
                )
            });
        }

        // Units per world axis (`space units`, the space directions'
        // components) or per volume axis (`units`, with `spacings`), to the
        // finest length unit among them (`shared/units.rs`).
        let unit = match header.get("space units") {
            Some(v) => {
                let u = quoted(path, "space units", v, space_dim.unwrap_or(3))?;
                let one = one_unit(&u[..3.min(u.len())], &["x", "y", "z"], notes);
                // Component c of every step and of the origin is along
                // world axis c.
                let f = DVec3::from_slice(&one.1);
                for step in &mut steps {
                    *step *= f;
                }
                origin *= f;
                one.0
            }
            None => match header.get("units") {
                Some(v) => {
                    let u = quoted(path, "units", v, dim)?;
                    let names = axes.map(|a| format!("axis {a}"));
                    let names = names.each_ref().map(String::as_str);
                    let one = one_unit(&axes.map(|a| u[a].clone()), &names, notes);
                    for i in 0..3 {
                        steps[i] *= one.1[i];
                        // Without space directions, origin i lies along axis i.
                        if directions.is_none() {
                            origin[i] *= one.1[i];
                        }
                    }
                    one.0
                }
                None => None,
            },
        };

        let mut ignored = Vec::new();
        for field in ["measurement frame", "old min", "old max", "thicknesses"] {
            if header.get(field).is_some() {
                ignored.push(field);
            }
        }
        if !ignored.is_empty() {
            notes.push(format!("fields not used: {}", ignored.join(", ")));
        }
        if !header.unknown.is_empty() {
            notes.push(format!(
                "fields not in the NRRD format ignored: {}",
                header.unknown.join(", ")
            ));
        }

        Ok(Geometry {
            frame_axis,
            axes,
            steps,
            origin,
            unit,
            kinds,
        })
    }
}

/// `units` (one per axis, named `names` in the notes) brought to one
/// length unit: that unit, if every axis is in a length unit, and each
/// axis's factor (1 for `???`, empty or non-length units). A unit shared
/// by every axis that is no length volray knows is still the volume's.
fn one_unit(
    units: &[String],
    names: &[&str],
    notes: &mut Vec<String>,
) -> (Option<String>, [f64; 3]) {
    let axes: Vec<AxisUnit> = units
        .iter()
        .zip(names)
        .map(|(u, &name)| AxisUnit {
            name,
            unit: Some(u.as_str()),
        })
        .collect();
    let one = one_length_unit(&axes);
    let first = units.first().map(|u| u.trim()).unwrap_or("");
    let shared = (!first.is_empty() && first != "???" && units.iter().all(|u| u.trim() == first))
        .then(|| first.to_string());
    let mut factors = [1.0; 3];
    for (f, g) in factors.iter_mut().zip(&one.factors) {
        *f = *g;
    }
    if shared.is_none() {
        notes.extend(one.notes);
    }
    (one.length_unit.or(shared), factors)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_meet_in_the_finest_length_unit() {
        let units = |u: &[&str]| u.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let mut notes = Vec::new();
        let one = one_unit(&units(&["mm", "mm", "mm"]), &["x", "y", "z"], &mut notes);
        assert_eq!(one, (Some("mm".into()), [1.0; 3]));
        let one = one_unit(&units(&["mm", "cm", "um"]), &["x", "y", "z"], &mut notes);
        assert_eq!(one, (Some("um".into()), [1000.0, 10000.0, 1.0]));
        assert_eq!(
            notes,
            ["x in mm, y in cm, z in um: spacing in um (x × 1000, y × 10000)"]
        );
        let one = one_unit(&units(&["???", "???", "???"]), &["x", "y", "z"], &mut notes);
        assert_eq!(one, (None, [1.0; 3]));
    }
}
