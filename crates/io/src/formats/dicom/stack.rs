//! Stacking DICOM slices into a grid: order along the slice normal,
//! equal spacing, consistent orientation and pixel spacing.
//!
//! Slice k's pixel (column i, row j) lies at
//! `IPP_k + i·Δc·row + j·Δr·col` (PS3.3 C.7.6.2.1.1), where `row` and
//! `col` are the two direction cosines of ImageOrientationPatient and
//! PixelSpacing = [Δr, Δc]. Slices are sorted by `IPP_k · n` with the
//! normal `n = row × col`, so index axes (i, j, k) form a right-handed
//! grid, and the slice step is `n` times the mean gap.

use volray_core::glam::DVec3;

use super::header::Plane;

/// Positions closer than this (mm) along the normal are the same slice.
const SAME_POSITION_MM: f64 = 1e-3;

/// Gaps may differ from their mean by this fraction of it, plus the
/// rounding of the positions ([`gap_tolerance`]), and still be read as
/// equal spacing at the mean gap, with a note naming the largest
/// deviation.
///
/// Why 5 %: ITK's ImageSeriesReader (itkImageSeriesReader.hxx,
/// GenerateData) reads any series, taking the gap between the first two
/// slices as the spacing and only warning ("Non uniform sampling or
/// missing slices detected") when a gap differs from it by more than
/// `SpacingWarningRelThreshold` (1e-4) of it; 3D Slicer loads such
/// series and offers to regularise them. MR scanners write
/// ImagePositionPatient rounded (to 0.01–0.1 mm, sometimes in single
/// precision), which makes gaps of a millimetre or two differ by a few
/// percent; a missing slice, the error worth refusing, makes one gap
/// twice the others, at least 50 % off the mean for any series of three
/// slices or more. 5 % keeps the scanner's rounding readable and stays an
/// order of magnitude below a missing slice; at the mean gap no slice lies
/// more than a few percent of a gap from its written position, which the
/// note states in mm.
const GAP_TOLERANCE: f64 = 0.05;

/// Gap differences above this fraction of the mean are reported in a note.
const GAP_NOTE: f64 = 1e-4;

/// A slice's in-plane shift per step may be this fraction of the step
/// (about 0.06 degrees of tilt).
const SHEAR_TOLERANCE: f64 = 1e-3;

/// Orientations agree if their direction cosines differ by at most this.
const ORIENTATION_TOLERANCE: f64 = 1e-4;

/// A sorted stack of slices as a grid.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Stack {
    /// Indices into the planes, in order along the normal.
    pub order: Vec<usize>,
    /// World step per index along columns, rows and slices.
    pub steps: [DVec3; 3],
    /// World position of the first pixel of the first slice.
    pub origin: DVec3,
    pub notes: Vec<String>,
}

/// Sorts `planes` into a grid. `name(i)` names plane i in messages
/// (a file name, or "frame 3"). Every plane needs a position and
/// orientation; the caller handles stacks without geometry.
pub(super) fn stack(planes: &[Plane], name: &dyn Fn(usize) -> String) -> Result<Stack, String> {
    let n = planes.len();
    if n < 2 {
        return Err(format!("{n} slice(s): a volume needs at least 2 slices"));
    }
    let mut positions = Vec::with_capacity(n);
    let mut orientation = None;
    let mut spacing: Option<[f64; 2]> = None;
    for (i, p) in planes.iter().enumerate() {
        let (Some(pos), Some(o)) = (p.position, p.orientation) else {
            return Err(format!(
                "{} has no ImagePositionPatient or ImageOrientationPatient, but other slices have: cannot order the slices",
                name(i)
            ));
        };
        positions.push(pos);
        match orientation {
            None => orientation = Some((o, i)),
            Some((first, j)) => {
                let differs =
                    (0..2).any(|a| (o[a] - first[a]).abs().max_element() > ORIENTATION_TOLERANCE);
                if differs {
                    return Err(format!(
                        "{} has ImageOrientationPatient {} but {} has {}: slices of one volume must share their orientation",
                        name(i),
                        cosines(o),
                        name(j),
                        cosines(first)
                    ));
                }
            }
        }
        let ps = p.pixel_spacing.unwrap_or([1.0, 1.0]);
        match spacing {
            None => spacing = Some(ps),
            Some(first) => {
                if (0..2).any(|a| (ps[a] - first[a]).abs() > 1e-6 * first[a]) {
                    return Err(format!(
                        "{} has PixelSpacing {}\\{} but the first slice has {}\\{}",
                        name(i),
                        ps[0],
                        ps[1],
                        first[0],
                        first[1]
                    ));
                }
            }
        }
    }
    let ([row, col], _) = orientation.expect("n >= 2 planes");
    let spacing = spacing.expect("n >= 2 planes");
    let normal = row.cross(col).normalize();
    let along: Vec<f64> = positions.iter().map(|p| p.dot(normal)).collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| along[a].total_cmp(&along[b]).then(a.cmp(&b)));

    let mut notes = Vec::new();
    let gaps: Vec<f64> = order
        .windows(2)
        .map(|w| along[w[1]] - along[w[0]])
        .collect();
    for (k, &g) in gaps.iter().enumerate() {
        if g < SAME_POSITION_MM {
            return Err(format!(
                "{} and {} lie at the same position ({} mm along the slice normal): the series holds more than one volume or duplicate slices",
                name(order[k]),
                name(order[k + 1]),
                along[order[k]]
            ));
        }
    }
    let mean = (along[order[n - 1]] - along[order[0]]) / (n - 1) as f64;
    let (kmin, gmin) = extreme(&gaps, |a, b| a < b);
    let (kmax, gmax) = extreme(&gaps, |a, b| a > b);
    let decimals = planes.iter().filter_map(|p| p.position_decimals).max();
    let (tolerance, stated) = gap_tolerance(mean, normal, decimals);
    let deviation = (gmax - mean).max(mean - gmin);
    let (kfar, gfar) = if gmax - mean >= mean - gmin {
        (kmax, gmax)
    } else {
        (kmin, gmin)
    };
    if deviation > tolerance {
        return Err(format!(
            "slice gaps are uneven: {} mm (between {} and {}) to {} mm (between {} and {}), mean {} mm; the gap of {} mm between {} and {} is {} mm ({} %) off the mean, beyond the tolerance of {} mm ({stated}): a slice may be missing, and volray needs equally spaced slices",
            round(gmin),
            name(order[kmin]),
            name(order[kmin + 1]),
            round(gmax),
            name(order[kmax]),
            name(order[kmax + 1]),
            round(mean),
            round(gfar),
            name(order[kfar]),
            name(order[kfar + 1]),
            round(deviation),
            percent(deviation / mean),
            round(tolerance),
        ));
    }
    if deviation > GAP_NOTE * mean {
        // The furthest slice from where the mean gap puts it.
        let (kpos, off) = (0..n)
            .map(|k| (k, along[order[k]] - (along[order[0]] + mean * k as f64)))
            .fold((0, 0.0f64), |best, (k, d)| {
                if d.abs() > best.1.abs() { (k, d) } else { best }
            });
        notes.push(format!(
            "slice gaps vary from {} to {} mm around their mean {} mm; the largest deviation is the gap of {} mm between {} and {}, {} mm ({} % of the mean) off it, within the tolerance of {} mm ({stated}): read at the mean gap, (last − first) / (n − 1), which places {} {} mm ({} % of a gap) from its written position, the furthest of any slice",
            round(gmin),
            round(gmax),
            round(mean),
            round(gfar),
            name(order[kfar]),
            name(order[kfar + 1]),
            round(deviation),
            percent(deviation / mean),
            round(tolerance),
            name(order[kpos]),
            round(off.abs()),
            percent(off.abs() / mean),
        ));
    }

    // Slices must stack straight along the normal (no gantry tilt).
    let step = (positions[order[n - 1]] - positions[order[0]]) / (n - 1) as f64;
    let shear = step - normal * step.dot(normal);
    if shear.length() > SHEAR_TOLERANCE * step.length() {
        return Err(format!(
            "each slice is shifted by ({:.4}, {:.4}, {:.4}) mm within its plane from the one before (gantry tilt?): volray needs slices stacked straight along their normal",
            shear.x, shear.y, shear.z
        ));
    }
    Ok(Stack {
        steps: [row * spacing[1], col * spacing[0], normal * mean],
        origin: positions[order[0]],
        order,
        notes,
    })
}

/// How far a gap may lie from the mean gap `mean` (mm) along unit
/// `normal`: [`GAP_TOLERANCE`] of the mean, plus what rounding the
/// positions to `decimals` decimals can do to a gap (each coordinate off by
/// at most half a unit of the last decimal, so a gap by one unit times the
/// normal's 1-norm); and that rule in words.
fn gap_tolerance(mean: f64, normal: DVec3, decimals: Option<u32>) -> (f64, String) {
    let percent = GAP_TOLERANCE * 100.0;
    match decimals {
        Some(d) if d <= 6 => {
            let rounding = 10f64.powi(-(d as i32)) * normal.abs().element_sum();
            (
                GAP_TOLERANCE * mean + rounding,
                format!(
                    "{percent} % of the mean gap plus {} mm for positions written to {d} decimal(s)",
                    round(rounding)
                ),
            )
        }
        _ => (GAP_TOLERANCE * mean, format!("{percent} % of the mean gap")),
    }
}

/// `x` to 6 significant decimals, for messages (gaps computed from decimal
/// strings carry binary noise: 1.2000000000000002).
fn round(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// A fraction as a percentage to two decimals, for messages.
fn percent(fraction: f64) -> f64 {
    (fraction * 1e4).round() / 1e2
}

/// The index and value of the extreme element under `better`.
fn extreme(values: &[f64], better: impl Fn(f64, f64) -> bool) -> (usize, f64) {
    let mut best = (0, values[0]);
    for (i, &v) in values.iter().enumerate().skip(1) {
        if better(v, best.1) {
            best = (i, v);
        }
    }
    best
}

fn cosines(o: [DVec3; 2]) -> String {
    format!(
        "{}\\{}\\{}\\{}\\{}\\{}",
        o[0].x, o[0].y, o[0].z, o[1].x, o[1].y, o[1].z
    )
}

/// Splits frames that repeat positions into volumes: if every position
/// occurs `m` times, volume `v` is the `v`-th occurrence of each position
/// in frame order. Returns the frame indices of each volume.
pub(super) fn volumes(planes: &[Plane]) -> Result<Vec<Vec<usize>>, String> {
    let normal = planes
        .iter()
        .find_map(|p| p.orientation)
        .map(|[r, c]| r.cross(c).normalize());
    // Group by position (exact positions within tolerance, not only the
    // component along the normal, so frames of different stacks differ).
    let mut groups: Vec<(DVec3, Vec<usize>)> = Vec::new();
    for (i, p) in planes.iter().enumerate() {
        let Some(pos) = p.position else {
            return Ok(vec![(0..planes.len()).collect()]);
        };
        match groups
            .iter_mut()
            .find(|(q, _)| (*q - pos).length() < SAME_POSITION_MM)
        {
            Some((_, members)) => members.push(i),
            None => groups.push((pos, vec![i])),
        }
    }
    let m = groups[0].1.len();
    if m == 1 {
        return Ok(vec![(0..planes.len()).collect()]);
    }
    if let Some((pos, members)) = groups.iter().find(|(_, g)| g.len() != m) {
        let along = normal.map(|n| pos.dot(n)).unwrap_or(pos.z);
        return Err(format!(
            "frames repeat positions unevenly: {m} frames at the first position but {} at {along} mm: cannot split them into volumes",
            members.len()
        ));
    }
    Ok((0..m)
        .map(|v| groups.iter().map(|(_, members)| members[v]).collect())
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(pos: DVec3, row: DVec3, col: DVec3) -> Plane {
        Plane {
            position: Some(pos),
            position_decimals: None,
            orientation: Some([row, col]),
            pixel_spacing: Some([0.8, 0.6]),
            slope: 1.0,
            intercept: 0.0,
        }
    }

    fn name(i: usize) -> String {
        format!("slice{i}")
    }

    #[test]
    fn sorts_along_the_normal_and_builds_steps() {
        // Sagittal: row +y, column -z, normal +y × -z = -x.
        let (row, col) = (DVec3::Y, -DVec3::Z);
        let xs = [3.0, 6.0, 0.0, 4.5, 1.5];
        let planes: Vec<Plane> = xs
            .iter()
            .map(|&x| plane(DVec3::new(x, 2.0, 7.0), row, col))
            .collect();
        let s = stack(&planes, &name).unwrap();
        // Ascending along -x: x = 6, 4.5, 3, 1.5, 0.
        assert_eq!(s.order, [1, 3, 0, 4, 2]);
        assert_eq!(s.origin, DVec3::new(6.0, 2.0, 7.0));
        assert_eq!(s.steps, [row * 0.6, col * 0.8, -DVec3::X * 1.5]);
        assert!(s.notes.is_empty());
    }

    #[test]
    fn uneven_duplicate_and_sheared_stacks_are_refused() {
        let z = |zs: &[f64]| -> Vec<Plane> {
            zs.iter()
                .map(|&z| plane(DVec3::new(0.0, 0.0, z), DVec3::X, DVec3::Y))
                .collect()
        };
        let err = stack(&z(&[0.0, 1.0, 2.0, 4.0, 5.0]), &name).unwrap_err();
        assert!(
            err.starts_with("slice gaps are uneven: 1 mm (between slice0 and slice1) to 2 mm (between slice2 and slice3), mean 1.25 mm"),
            "{err}"
        );
        let err = stack(&z(&[0.0, 1.0, 1.0]), &name).unwrap_err();
        assert!(
            err.contains("slice1 and slice2 lie at the same position"),
            "{err}"
        );
        // Jitter under 1% is accepted with a note.
        let s = stack(&z(&[0.0, 1.0, 2.005, 3.0]), &name).unwrap();
        assert!(s.notes[0].contains("vary from 0.995"), "{:?}", s.notes);
        assert!((s.steps[2].z - 1.0).abs() < 1e-12);
        // 20 % uneven: still refused, naming the slices and how far off.
        let err = stack(&z(&[0.0, 1.0, 2.2, 3.0]), &name).unwrap_err();
        assert!(
            err.contains("between slice1 and slice2")
                && err.contains("0.2 mm (20 %) off the mean, beyond the tolerance of 0.05 mm (5 % of the mean gap)"),
            "{err}"
        );

        let tilted: Vec<Plane> = (0..3)
            .map(|k| {
                plane(
                    DVec3::new(0.0, 0.3 * k as f64, k as f64),
                    DVec3::X,
                    DVec3::Y,
                )
            })
            .collect();
        let err = stack(&tilted, &name).unwrap_err();
        assert!(err.contains("(0.0000, 0.3000, 0.0000) mm"), "{err}");

        let mut mixed = z(&[0.0, 1.0, 2.0]);
        mixed[2].orientation = Some([DVec3::Y, DVec3::X]);
        let err = stack(&mixed, &name).unwrap_err();
        assert!(
            err.contains("slice2 has ImageOrientationPatient 0\\1\\0\\1\\0\\0"),
            "{err}"
        );
        let mut spacing = z(&[0.0, 1.0]);
        spacing[1].pixel_spacing = Some([0.8, 0.7]);
        let err = stack(&spacing, &name).unwrap_err();
        assert!(err.contains("PixelSpacing 0.8\\0.7"), "{err}");
        assert!(stack(&z(&[0.0]), &name).unwrap_err().contains("at least 2"));
    }

    #[test]
    fn near_even_gaps_are_read_at_the_mean_gap_naming_the_largest_deviation() {
        // Slice 2 written 0.03 mm off: gaps 1, 1.03, 0.97 mm, 3 % off.
        let planes: Vec<Plane> = [0.0, 1.0, 2.03, 3.0]
            .iter()
            .map(|&z| plane(DVec3::new(0.0, 0.0, z), DVec3::X, DVec3::Y))
            .collect();
        let s = stack(&planes, &name).unwrap();
        assert!((s.steps[2].z - 1.0).abs() < 1e-12);
        assert_eq!(s.origin, DVec3::ZERO);
        assert_eq!(s.notes.len(), 1);
        let note = &s.notes[0];
        assert!(
            note.contains("slice gaps vary from 0.97 to 1.03 mm around their mean 1 mm")
                && note.contains("0.03 mm (3 % of the mean) off it, within the tolerance of 0.05 mm (5 % of the mean gap)")
                && note.contains("places slice2 0.03 mm (3 % of a gap) from its written position"),
            "{note}"
        );
    }

    #[test]
    fn rounded_positions_widen_the_gap_tolerance() {
        // 1.15 mm steps written with one decimal: gaps 1.1 and 1.2 mm.
        let zs = [10.0, 11.2, 12.3, 13.5, 14.6, 15.8];
        let rounded = |decimals: Option<u32>| -> Vec<Plane> {
            zs.iter()
                .map(|&z| Plane {
                    position_decimals: decimals,
                    ..plane(DVec3::new(0.0, 0.0, z), DVec3::X, DVec3::Y)
                })
                .collect()
        };
        // Gaps 1.1 and 1.2 mm: 0.06 mm (5.17 %) off their mean 1.16 mm.
        let s = stack(&rounded(Some(1)), &name).unwrap();
        assert!((s.steps[2].z - 1.16).abs() < 1e-12);
        assert!(
            s.notes[0].contains("tolerance of 0.158 mm"),
            "{:?}",
            s.notes
        );
        // Written with more decimals, the same gaps are uneven.
        let err = stack(&rounded(Some(3)), &name).unwrap_err();
        assert!(err.contains("beyond the tolerance of 0.059 mm (5 % of the mean gap plus 0.001 mm for positions written to 3 decimal(s))"), "{err}");
        let err = stack(&rounded(None), &name).unwrap_err();
        assert!(
            err.contains(
                "is 0.06 mm (5.17 %) off the mean, beyond the tolerance of 0.058 mm (5 % of the mean gap)"
            ),
            "{err}"
        );
        // An oblique normal: rounding moves a gap by a unit per component.
        let (_, stated) = gap_tolerance(1.0, DVec3::new(0.6, 0.0, 0.8), Some(2));
        assert_eq!(
            stated,
            "5 % of the mean gap plus 0.014 mm for positions written to 2 decimal(s)"
        );
    }

    #[test]
    fn repeated_positions_split_into_volumes() {
        let at = |z: f64| plane(DVec3::new(0.0, 0.0, z), DVec3::X, DVec3::Y);
        let frames: Vec<Plane> = [0.0, 1.0, 2.0, 0.0, 1.0, 2.0].map(at).to_vec();
        assert_eq!(volumes(&frames).unwrap(), [vec![0, 1, 2], vec![3, 4, 5]]);
        let single: Vec<Plane> = [2.0, 0.0, 1.0].map(at).to_vec();
        assert_eq!(volumes(&single).unwrap(), [vec![0, 1, 2]]);
        let uneven: Vec<Plane> = [0.0, 1.0, 0.0].map(at).to_vec();
        assert!(volumes(&uneven).unwrap_err().contains("unevenly"));
    }
}
