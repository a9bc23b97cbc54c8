//! Length units: the spatial axes of a file brought to one unit.
//!
//! A file may give each spatial axis its own unit (OME-Zarr `axes`,
//! OME-TIFF `PhysicalSize{X,Y,Z}Unit`, CF coordinate variables' `units`,
//! NRRD `space units`, MINC dimensions' `units`, FITS `CUNITn`). volray's
//! volume has one spacing per axis and one
//! [`FileInfo::length_unit`](crate::FileInfo), so every reader sends its
//! axes through [`one_length_unit`], which applies one rule:
//!
//! - **lengths are converted to the finest length unit among the axes**
//!   (z in micrometer, y and x in nanometer: spacing in nanometer). The
//!   finest, not the first axis's, because the factor is then a whole
//!   number (1000, not 0.001) for every metric pair, and multiplying by a
//!   whole power of ten keeps a spacing written as 100 at 100 exactly
//!   and ratios between axes exact; the unit is kept as the file
//!   spells it (`micrometer`, `µm`, `um`);
//! - units that are not lengths (`degrees_north`, `hPa`, `s`, or a length
//!   volray does not know) are **kept apart**: that axis's spacing and
//!   origin stay in its own unit, and a note says so; the volume then has
//!   no `length_unit`, as it has none where an axis has no unit at all.
//!
//! What was converted, and what was not, goes to the notes in words
//! (`z in micrometer, y/x in nanometer: spacing in nanometer (z × 1000)`).

/// Metres per one of a length unit, or `None` where `unit` is not a
/// length volray knows. The names: SI symbols, their long names in
/// either spelling and plural (CF's UDUNITS-2 and OME-Zarr's axes use
/// `micrometer`, `nanometer`, `angstrom`; OME-XML `µm`, `Å`), the micro
/// sign (U+00B5) and the Greek mu (U+03BC) alike.
pub(crate) fn metres(unit: &str) -> Option<f64> {
    let symbol = unit.trim();
    let lower = symbol.to_lowercase();
    let long = lower
        .strip_suffix('s')
        .unwrap_or(&lower)
        .replace("metre", "meter");
    Some(match (symbol, long.as_str()) {
        ("km", _) | (_, "kilometer") => 1e3,
        ("hm", _) | (_, "hectometer") => 1e2,
        ("m", _) | (_, "meter") => 1.0,
        ("dm", _) | (_, "decimeter") => 1e-1,
        ("cm", _) | (_, "centimeter") => 1e-2,
        ("mm", _) | (_, "millimeter") => 1e-3,
        ("µm" | "μm" | "um", _) | (_, "micrometer" | "micron") => 1e-6,
        ("nm", _) | (_, "nanometer") => 1e-9,
        ("pm", _) | (_, "picometer") => 1e-12,
        // The letter Å (U+00C5), as OME writes it, and the angstrom sign.
        ("\u{c5}" | "\u{212b}", _) | (_, "angstrom" | "ångström") => 1e-10,
        ("in", _) | (_, "inch" | "inche") => 0.0254,
        ("ft", _) | (_, "foot" | "feet") => 0.3048,
        // Astronomy's (FITS Standard 4.0, Table 4): the IAU 2012 au, the
        // parsec from it, the Julian light year.
        ("AU" | "au", _) => 1.495_978_707e11,
        ("pc", _) | (_, "parsec") => 3.085_677_581_491_367e16,
        ("kpc", _) => 3.085_677_581_491_367e19,
        ("Mpc", _) => 3.085_677_581_491_367e22,
        ("lyr", _) => 9.460_730_472_580_8e15,
        _ => return None,
    })
}

/// Whether `unit` is one of pressure (UDUNITS-2 names and symbols), as
/// CF vertical coordinates on pressure levels carry.
pub(crate) fn is_pressure(unit: &str) -> bool {
    matches!(
        unit.trim().to_ascii_lowercase().as_str(),
        "pa" | "hpa"
            | "kpa"
            | "mbar"
            | "millibar"
            | "millibars"
            | "mb"
            | "bar"
            | "atm"
            | "pascal"
            | "pascals"
            | "hectopascal"
            | "hectopascals"
    )
}

/// The factor that takes a length in a unit of `from` metres to one of
/// `to` metres: a whole number where the ratio is one to rounding (1e-6 /
/// 1e-9 is 1000, not 999.9999999999999), so that values converted to a
/// finer unit are exact products.
pub(crate) fn factor(from: f64, to: f64) -> f64 {
    let r = from / to;
    if r >= 1.0 && (r.round() - r).abs() <= 1e-9 * r {
        r.round()
    } else if r < 1.0 && ((1.0 / r).round() - 1.0 / r).abs() <= 1e-9 / r {
        1.0 / (1.0 / r).round()
    } else {
        r
    }
}

/// One spatial axis as the file describes it: its name in the notes
/// (`"x"`, `"lat"`) and its unit as written, if any.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct AxisUnit<'a> {
    pub name: &'a str,
    pub unit: Option<&'a str>,
}

/// The axes brought to one length unit (see the module doc).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct OneUnit {
    /// Per axis, in the order given: what its spacing and origin are
    /// multiplied by (1 for the finest unit, and for an axis that is not
    /// in a length unit).
    pub factors: Vec<f64>,
    /// The unit of every axis's spacing and origin once converted: the
    /// finest length unit, as the file spells it; `None` where an axis has
    /// no unit or one that is not a length.
    pub length_unit: Option<String>,
    /// What was converted and what was kept apart, for `volray info`
    /// (empty where every axis has the same unit or none has one).
    pub notes: Vec<String>,
    /// Per axis, in the order given, where some axis has a unit that is
    /// not a length and the units differ (degrees by metres): its unit
    /// once converted (a length axis's is the finest length unit), `None`
    /// for an axis without one; empty otherwise. What the display scale
    /// stretches ([`FileInfo::axis_units`](crate::FileInfo)).
    pub apart: Vec<Option<String>>,
}

/// Brings `axes` to one length unit: the finest of their length units
/// (see the module doc). Units that are empty or `???` count as none.
pub(crate) fn one_length_unit(axes: &[AxisUnit]) -> OneUnit {
    let units: Vec<Option<&str>> = axes
        .iter()
        .map(|a| {
            a.unit
                .map(str::trim)
                .filter(|u| !u.is_empty() && *u != "???")
        })
        .collect();
    let lengths: Vec<Option<f64>> = units.iter().map(|u| u.and_then(metres)).collect();
    // The finest length unit; the first axis in it names it.
    let finest = lengths
        .iter()
        .enumerate()
        .filter_map(|(a, m)| m.map(|m| (a, m)))
        .fold(None::<(usize, f64)>, |best, (a, m)| match best {
            Some((_, b)) if b <= m => best,
            _ => Some((a, m)),
        });
    let mut factors = vec![1.0; axes.len()];
    let mut notes = Vec::new();
    let all_lengths = lengths.iter().all(Option::is_some);
    let length_unit =
        finest.and_then(|(a, _)| all_lengths.then(|| units[a].unwrap_or("").to_string()));

    // The axes grouped by unit as written, in order of first appearance.
    let mut groups: Vec<(Option<&str>, Vec<&str>)> = Vec::new();
    for (a, u) in units.iter().enumerate() {
        match groups.iter_mut().find(|(g, _)| g == u) {
            Some((_, names)) => names.push(axes[a].name),
            None => groups.push((*u, vec![axes[a].name])),
        }
    }
    let in_units = |want: &dyn Fn(usize) -> bool| -> Vec<String> {
        groups
            .iter()
            .filter_map(|(u, names)| {
                let a = units.iter().position(|x| x == u)?;
                (want(a) && u.is_some())
                    .then(|| format!("{} in {}", names.join("/"), u.unwrap_or("")))
            })
            .collect()
    };

    if let Some((at, to)) = finest {
        let target = units[at].unwrap_or("");
        let mut converted = Vec::new();
        for (a, m) in lengths.iter().enumerate() {
            if let Some(from) = m
                && *from != to
            {
                factors[a] = factor(*from, to);
                converted.push(format!("{} × {}", axes[a].name, factors[a]));
            }
        }
        if !converted.is_empty() {
            notes.push(format!(
                "{}: spacing in {target} ({})",
                in_units(&|a| lengths[a].is_some()).join(", "),
                converted.join(", ")
            ));
        }
    }
    let others = in_units(&|a| lengths[a].is_none());
    if !others.is_empty() {
        notes.push(format!(
            "{}: not length units, kept as written (not converted); the spacing mixes units",
            others.join(", ")
        ));
    }
    let without: Vec<&str> = (0..axes.len())
        .filter(|&a| units[a].is_none())
        .map(|a| axes[a].name)
        .collect();
    if !without.is_empty() && without.len() < axes.len() {
        notes.push(format!(
            "{} without a unit: {} kept as written",
            without.join("/"),
            if without.len() == 1 {
                "its spacing"
            } else {
                "their spacing"
            }
        ));
    }
    // Kept apart: after conversion, the axes with units are in more than
    // one unit, one of them not a length.
    let converted: Vec<Option<String>> = (0..axes.len())
        .map(|a| match (lengths[a], finest) {
            (Some(_), Some((at, _))) => units[at].map(str::to_string),
            _ => units[a].map(str::to_string),
        })
        .collect();
    let mut distinct: Vec<&str> = converted.iter().flatten().map(String::as_str).collect();
    distinct.sort_unstable();
    distinct.dedup();
    let apart = if distinct.len() > 1
        && lengths
            .iter()
            .zip(&units)
            .any(|(m, u)| m.is_none() && u.is_some())
    {
        converted
    } else {
        Vec::new()
    };
    OneUnit {
        factors,
        length_unit,
        notes,
        apart,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axes<'a>(list: &[(&'a str, Option<&'a str>)]) -> Vec<AxisUnit<'a>> {
        list.iter()
            .map(|&(name, unit)| AxisUnit { name, unit })
            .collect()
    }

    #[test]
    fn mixed_lengths_go_to_the_finest_by_whole_factors() {
        let one = one_length_unit(&axes(&[
            ("z", Some("micrometer")),
            ("y", Some("nanometer")),
            ("x", Some("nanometer")),
        ]));
        assert_eq!(one.factors, [1000.0, 1.0, 1.0]);
        assert_eq!(one.length_unit.as_deref(), Some("nanometer"));
        assert!(one.apart.is_empty(), "lengths are one unit once converted");
        assert_eq!(
            one.notes,
            ["z in micrometer, y/x in nanometer: spacing in nanometer (z × 1000)"]
        );
        // 0.3 µm is 300 nm exactly.
        assert_eq!(0.3 * one.factors[0], 300.0);
    }

    #[test]
    fn one_unit_needs_no_note_and_names_itself_as_written() {
        let one = one_length_unit(&axes(&[
            ("x", Some("µm")),
            ("y", Some("µm")),
            ("z", Some("µm")),
        ]));
        assert_eq!(one.factors, [1.0; 3]);
        assert_eq!(one.length_unit.as_deref(), Some("µm"));
        assert!(one.notes.is_empty());
        // Spellings of one unit are one unit: no factor but 1.
        let one = one_length_unit(&axes(&[
            ("x", Some("mm")),
            ("y", Some("millimetres")),
            ("z", Some("mm")),
        ]));
        assert_eq!(one.factors, [1.0; 3]);
        assert_eq!(one.length_unit.as_deref(), Some("mm"));
    }

    #[test]
    fn units_that_are_not_lengths_are_kept_apart() {
        let one = one_length_unit(&axes(&[
            ("lon", Some("degrees_east")),
            ("lat", Some("degrees_north")),
            ("lev", Some("hPa")),
        ]));
        assert_eq!(one.factors, [1.0; 3]);
        assert_eq!(one.length_unit, None);
        assert_eq!(
            one.notes,
            [
                "lon in degrees_east, lat in degrees_north, lev in hPa: not length units, kept as written (not converted); the spacing mixes units"
            ]
        );
        // Lengths beside them are still brought to one unit.
        let one = one_length_unit(&axes(&[
            ("x", Some("km")),
            ("y", Some("m")),
            ("depth", Some("degrees")),
        ]));
        assert_eq!(one.factors, [1000.0, 1.0, 1.0]);
        assert_eq!(one.length_unit, None);
        assert_eq!(one.notes[0], "x in km, y in m: spacing in m (x × 1000)");
        let m = Some("m".to_string());
        assert_eq!(one.apart, [m.clone(), m, Some("degrees".into())]);
        assert!(one.notes[1].starts_with("depth in degrees: not length units"));
    }

    #[test]
    fn axes_without_units_are_named() {
        let one = one_length_unit(&axes(&[("x", Some("mm")), ("y", Some("")), ("z", None)]));
        assert_eq!(one.length_unit, None);
        assert_eq!(
            one.notes,
            ["y/z without a unit: their spacing kept as written"]
        );
        assert!(
            one_length_unit(&axes(&[("x", None), ("y", None)]))
                .notes
                .is_empty()
        );
    }

    #[test]
    fn factors_are_whole_where_the_ratio_is() {
        assert_eq!(factor(1e-6, 1e-9), 1000.0);
        assert_eq!(factor(1e-3, 1e-10), 1e7);
        assert_eq!(factor(1e-9, 1e-6), 0.001);
        assert_eq!(factor(0.0254, 1e-3), 25.4);
        assert_eq!(metres("Micrometres"), Some(1e-6));
        assert_eq!(metres("\u{3bc}m"), Some(1e-6));
        assert_eq!(metres("hPa"), None);
    }
}
