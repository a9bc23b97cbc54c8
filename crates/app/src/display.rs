//! The display scale: each world axis stretched for drawing, not for
//! reading (issue 43 item 8; issue 46 item 3 builds on the same names).
//!
//! A file whose axes are in units that are not one length (a CF file's
//! lon and lat in degrees by a level in m or Pa: volray-io's `units.rs`
//! keeps them apart, [`FileInfo::axis_units`]) has a box whose extents
//! are not comparable: 7.5 degrees by 2 degrees by 300 m is drawn as a
//! line. By default such axes are stretched ([`stretch`]): the axes are
//! grouped by the kind of their unit (every length is one kind, once
//! converted to one unit; every spelling of degrees one; any other unit
//! its own; an axis without a unit its own), the group with the most
//! axes (ties: x's) is the reference and is kept as stored, so that a
//! map keeps its shape, and every other group is scaled by one factor
//! so that its longest axis spans the mean extent of the reference's
//! axes, rounded to two significant digits (so that the note's factor
//! is exact, and `--scale` with it draws the same picture). The box's
//! extents are then within the reference's own aspect of one another,
//! never a line. `--scale X,Y,Z` (Python `scale=`) sets the factors
//! instead; `--scale 1,1,1` draws the axes as stored. Files with one
//! length unit, or no units at all, are not stretched (their pictures
//! are unchanged to the bit).
//!
//! The stretch multiplies the volume's spacing and origin (world
//! coordinates become display coordinates: `--look-at`, `--crop` and
//! `--clip` are in them too). It applies where an input is opened for
//! rendering (`input::load_log`, the MPI ranks' sources, a chunked level
//! rendered in pieces through [`Stretched`]), not where it is read for
//! its values (`volray info`, `convert`, Python's `read`).

use std::sync::Arc;
use volray_core::glam::DVec3;
use volray_core::sampling::grid::GridFrame;
use volray_core::{SampleType, SourceError, SourceErrorKind, Volume, VolumeSource};
use volray_io::FileInfo;

/// How the axes are stretched for drawing.
#[derive(Debug, Clone, PartialEq)]
pub struct Stretch {
    /// What each world axis's spacing and origin are multiplied by.
    pub factors: [f64; 3],
    /// The note that says so, for stderr and `volray info`'s notes; none
    /// for a stretch the front end was given.
    pub note: Option<String>,
}

/// The stretch of a volume whose file says `info` and whose box spans
/// `extent` (the stored world extents): `explicit` (`--scale`) where
/// given, else the default rule (the module doc) where the axes' units
/// differ; `None` where nothing is stretched.
pub fn stretch(
    info: Option<&FileInfo>,
    extent: DVec3,
    explicit: Option<[f64; 3]>,
) -> Option<Stretch> {
    if let Some(factors) = explicit {
        return (factors != [1.0; 3]).then_some(Stretch {
            factors,
            note: None,
        });
    }
    let axes = info?.axis_units.as_ref()?;
    let kinds: Vec<String> = axes.iter().map(|a| kind(a.unit.as_deref())).collect();
    let extent = extent.to_array().map(f64::abs);
    // The groups in order of first appearance; the reference has the most
    // axes, the first (x's) among equals.
    let mut groups: Vec<(&str, Vec<usize>)> = Vec::new();
    for (a, k) in kinds.iter().enumerate() {
        match groups.iter_mut().find(|(g, _)| g == k) {
            Some((_, members)) => members.push(a),
            None => groups.push((k, vec![a])),
        }
    }
    if groups.len() < 2 {
        return None;
    }
    let reference = (0..groups.len())
        .rev()
        .max_by_key(|&g| groups[g].1.len())
        .expect("two groups");
    let members = &groups[reference].1;
    let mean = members.iter().map(|&a| extent[a]).sum::<f64>() / members.len() as f64;
    if !(mean.is_finite() && mean > 0.0) {
        return None;
    }
    let first = members[0];
    let in_unit = axes[first].unit.as_deref().unwrap_or("(no unit)");
    let mut factors = [1.0; 3];
    let mut said = Vec::new();
    for (g, (_, members)) in groups.iter().enumerate() {
        let longest = members.iter().map(|&a| extent[a]).fold(0.0, f64::max);
        if g == reference || !(longest.is_finite() && longest > 0.0) {
            continue;
        }
        let s = two_digits(mean / longest);
        for &a in members {
            factors[a] = s;
            let axis = &axes[a];
            said.push(match &axis.unit {
                Some(u) => format!(
                    "{} ({}, {u}) drawn at 1 {u} = {s} {in_unit}",
                    NAMES[a], axis.name
                ),
                None => format!(
                    "{} ({}, no unit) drawn at 1 = {s} {in_unit}",
                    NAMES[a], axis.name
                ),
            });
        }
    }
    if factors == [1.0; 3] {
        return None;
    }
    let [x, y, z] = factors;
    Some(Stretch {
        factors,
        note: Some(format!(
            "{}: axes in different units, each drawn to span about the mean extent of {} ({}); --scale {x},{y},{z} is this stretch, --scale 1,1,1 draws them as stored",
            said.join("; "),
            members
                .iter()
                .map(|&a| NAMES[a])
                .collect::<Vec<_>>()
                .join(", "),
            members
                .iter()
                .map(|&a| axes[a].name.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        )),
    })
}

/// The world axes' names in the notes.
const NAMES: [&str; 3] = ["x", "y", "z"];

/// The kind of a unit: every spelling of degrees one kind (CF's
/// `degrees_east` and `degrees_north` are the same angle, UDUNITS-2's
/// `degree`, `deg`, `°`), any other unit as written (lengths are one
/// unit already, volray-io's `units.rs`), no unit its own kind.
fn kind(unit: Option<&str>) -> String {
    let Some(u) = unit.map(str::trim) else {
        return String::new();
    };
    let lower = u.to_ascii_lowercase();
    if lower.starts_with("degree") || lower == "deg" || u == "°" {
        "degrees".into()
    } else {
        u.to_string()
    }
}

/// `v` rounded to two significant digits, exactly as its decimal reads
/// (0.0158 to 0.016; 1234 to 1200).
fn two_digits(v: f64) -> f64 {
    let e = v.log10().floor() as i32 - 1;
    if e >= 0 {
        (v / 10f64.powi(e)).round() * 10f64.powi(e)
    } else {
        (v * 10f64.powi(-e)).round() / 10f64.powi(-e)
    }
}

/// `volume` in the stretched world: its spacing and origin multiplied by
/// `factors`, the samples as they are (refused where a factor is not a
/// positive number).
pub fn stretched(volume: Volume, factors: [f64; 3]) -> Result<Volume, volray_core::VolumeError> {
    let f = DVec3::from(factors);
    if !(f.is_finite() && f.min_element() > 0.0) {
        return Err(volray_core::VolumeError::BadSpacing(f.x, f.y, f.z));
    }
    let (spacing, origin) = (volume.spacing() * f, volume.origin() * f);
    volume
        .with_spacing(spacing)
        .and_then(|v| v.with_origin(origin))
}

/// A source's boxes placed in the stretched world (a chunked level
/// rendered in pieces: `plan.rs`): its grid's and each box's spacing and
/// origin multiplied by `factors`, the samples as read.
pub struct Stretched {
    inner: Arc<dyn VolumeSource>,
    factors: DVec3,
}

impl Stretched {
    /// `inner` stretched by `factors` (positive, finite: [`stretch`]'s).
    pub fn new(inner: Arc<dyn VolumeSource>, factors: [f64; 3]) -> Stretched {
        Stretched {
            inner,
            factors: DVec3::from(factors),
        }
    }
}

impl VolumeSource for Stretched {
    fn grid(&self) -> GridFrame {
        let g = self.inner.grid();
        GridFrame {
            dims: g.dims,
            origin: g.origin * self.factors,
            spacing: g.spacing * self.factors,
        }
    }

    fn sample_type(&self) -> SampleType {
        self.inner.sample_type()
    }

    fn is_labels(&self) -> bool {
        self.inner.is_labels()
    }

    fn voxel_bytes(&self) -> usize {
        self.inner.voxel_bytes()
    }

    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, SourceError> {
        let v = self.inner.read_box(lo, hi)?;
        let (spacing, origin) = (v.spacing() * self.factors, v.origin() * self.factors);
        (v.with_spacing(spacing))
            .and_then(|v| v.with_origin(origin))
            .map_err(|e| SourceError::new(SourceErrorKind::BadData, format!("scale: {e}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use volray_io::AxisUnitName;

    fn info(units: [(&str, Option<&str>); 3]) -> FileInfo {
        FileInfo {
            axis_units: Some(units.map(|(name, unit)| AxisUnitName {
                name: name.into(),
                unit: unit.map(String::from),
            })),
            ..FileInfo::new("int16")
        }
    }

    #[test]
    fn a_level_in_metres_under_degrees_spans_the_mean_of_lon_and_lat() {
        let i = info([
            ("lon", Some("degrees_east")),
            ("lat", Some("degrees_north")),
            ("lev", Some("m")),
        ]);
        // 7.5 by 2 degrees, 300 m: the level drawn 4.75 degrees tall,
        // 4.75 / 300 = 0.01583 rounded to 0.016.
        let s = stretch(Some(&i), DVec3::new(7.5, -2.0, 300.0), None).unwrap();
        assert_eq!(s.factors, [1.0, 1.0, 0.016]);
        assert_eq!(
            s.note.unwrap(),
            "z (lev, m) drawn at 1 m = 0.016 degrees_east: axes in different units, each drawn to span about the mean extent of x, y (lon, lat); --scale 1,1,0.016 is this stretch, --scale 1,1,1 draws them as stored"
        );
    }

    #[test]
    fn the_scale_given_wins_and_one_unit_is_never_stretched() {
        let i = info([("x", Some("hPa")), ("y", Some("m")), ("z", Some("m"))]);
        // The metres are the reference (two axes); hPa spans their mean.
        let s = stretch(Some(&i), DVec3::new(500.0, 10.0, 30.0), None).unwrap();
        assert_eq!(s.factors, [0.04, 1.0, 1.0]);
        let given = stretch(Some(&i), DVec3::ONE, Some([1.0, 2.0, 3.0])).unwrap();
        assert_eq!((given.factors, given.note), ([1.0, 2.0, 3.0], None));
        assert_eq!(stretch(Some(&i), DVec3::ONE, Some([1.0; 3])), None);
        // No axis units kept apart (one length unit, or none): as stored.
        assert_eq!(
            stretch(Some(&FileInfo::new("u8")), DVec3::new(1.0, 1.0, 1e6), None),
            None
        );
        assert_eq!(stretch(None, DVec3::new(1.0, 1.0, 1e6), None), None);
        // Degrees of longitude and latitude are one kind.
        let map = info([
            ("lon", Some("degrees_east")),
            ("lat", Some("degrees_north")),
            ("t", Some("degree")),
        ]);
        assert_eq!(stretch(Some(&map), DVec3::new(1.0, 1.0, 1e6), None), None);
    }

    #[test]
    fn two_digits_read_as_written() {
        assert_eq!(two_digits(4.75 / 300.0), 0.016);
        assert_eq!(two_digits(1234.0), 1200.0);
        assert_eq!(two_digits(0.00356), 0.0036);
        assert_eq!(two_digits(7.0), 7.0);
    }
}
