//! A FITS image's linear world coordinates (FITS Standard 4.0, §8;
//! Greisen & Calabretta 2002, "Representations of world coordinates in
//! FITS", A&A 395, 1061) turned into volray's grid: the world coordinate
//! along axis i of the pixel p (1-based, §8.1)
//!
//! ```text
//! w_i = CRVAL_i + Σ_j M_ij (p_j − CRPIX_j),   M_ij = CD_ij, or CDELT_i · PC_ij
//! ```
//!
//! with CRPIX 0, CRVAL 0, CDELT 1 and PC the identity where absent (§8.2,
//! Table 22). Sample (i, j, k) is pixel (i + 1, j + 1, k + 1), so index
//! axis j steps by column j of M, and sample (0, 0, 0) lies at
//! CRVAL + M·(1 − CRPIX).
//!
//! Whether those are the volume's spacing and origin depends on the units
//! (see [`Geometry`]): a radio cube's axes (RA and Dec in degrees,
//! frequency in Hz or velocity in m/s) are not one length, and the tools
//! astronomers render cubes with draw them in pixel coordinates: ds9's 3-D
//! frame and SlicerAstro render the index grid, and yt's FITS frontend
//! lays a spectral cube out in pixels (1 to N, with `spectral_factor` to
//! stretch the spectral axis, 1 by default). So volray uses the world
//! coordinates only where all three axes share one kind of unit (lengths,
//! or angles) and none is spectral; otherwise it renders the pixel grid
//! (spacing 1, sample 1 at 1: FITS's and ds9's "image" coordinates, yt's
//! cell centres), and the notes say where each axis's world coordinates
//! start and how they step.

use volray_core::glam::DVec3;

use super::header::Header;
use crate::shared::units::{AxisUnit, one_length_unit};

/// The grid the reader hands to `grid_to_volume` (or resamples, where the
/// steps are not orthogonal).
pub(super) struct Geometry {
    /// The world step of each index axis, and the world position of
    /// sample (0, 0, 0).
    pub steps: [DVec3; 3],
    pub origin: DVec3,
    /// The unit of spacing and origin: a CUNIT, or `pixel`.
    pub unit: Option<String>,
    pub notes: Vec<String>,
}

/// The kind of quantity a unit measures, and its size in a base unit
/// (metres, degrees) where volray knows it.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Dimension {
    Length(f64),
    Angle(f64),
    Other,
}

/// Units of length and angle FITS headers use (§4.3, Table 3 and 4).
fn dimension(unit: &str) -> Dimension {
    let length = match unit {
        "m" => 1.0,
        "mm" => 1e-3,
        "cm" => 1e-2,
        "km" => 1e3,
        "um" => 1e-6,
        "nm" => 1e-9,
        "Angstrom" | "angstrom" => 1e-10,
        "AU" | "au" => 1.495_978_707e11,
        "pc" => 3.085_677_581_491_367e16,
        "kpc" => 3.085_677_581_491_367e19,
        "Mpc" => 3.085_677_581_491_367e22,
        "lyr" => 9.460_730_472_580_8e15,
        _ => 0.0,
    };
    if length > 0.0 {
        return Dimension::Length(length);
    }
    match unit {
        "deg" => Dimension::Angle(1.0),
        "arcmin" => Dimension::Angle(1.0 / 60.0),
        "arcsec" => Dimension::Angle(1.0 / 3600.0),
        "mas" => Dimension::Angle(1.0 / 3.6e6),
        "rad" => Dimension::Angle(180.0 / std::f64::consts::PI),
        _ => Dimension::Other,
    }
}

/// The axis type before its projection code: `RA` of `RA---SIN`.
fn type_stem(ctype: &str) -> &str {
    ctype.split('-').next().unwrap_or("").trim()
}

/// Spectral axis types (Greisen et al. 2006, A&A 446, 747, Table 1), and
/// the other non-spatial ones.
fn is_spectral_or_other(ctype: &str) -> bool {
    matches!(
        type_stem(ctype),
        "FREQ"
            | "ENER"
            | "WAVN"
            | "VRAD"
            | "WAVE"
            | "VOPT"
            | "ZOPT"
            | "AWAV"
            | "VELO"
            | "BETA"
            | "FELO"
            | "VELOCITY"
            | "STOKES"
            | "TIME"
            | "UTC"
            | "TAI"
    )
}

/// Celestial longitude and latitude types (§8.3), whose unit is degrees
/// where CUNIT is absent.
fn is_celestial(ctype: &str) -> bool {
    let stem = type_stem(ctype);
    matches!(stem, "RA" | "DEC")
        || (stem.len() == 4 && (stem.ends_with("LON") || stem.ends_with("LAT")))
}

/// A unit where CUNIT gives none: the standard's default for the axis type.
fn default_unit(ctype: &str) -> &'static str {
    if is_celestial(ctype) {
        return "deg";
    }
    match type_stem(ctype) {
        "FREQ" => "Hz",
        "WAVE" | "AWAV" => "m",
        "VRAD" | "VOPT" | "VELO" | "FELO" => "m/s",
        "ENER" => "J",
        "WAVN" => "/m",
        _ => "",
    }
}

/// The geometry of the image whose file axes `axes` (1-based NAXIS
/// numbers) are the volume's x, y, z. `Err` names the keyword at fault.
pub(super) fn geometry(h: &Header, axes: [usize; 3]) -> Result<Geometry, String> {
    let num = |key: String, default: f64| -> Result<f64, String> {
        Ok(h.float(&key)?.unwrap_or(default))
    };
    let mut ctype = Vec::new();
    let mut unit = Vec::new();
    let (mut crpix, mut crval) = ([0.0; 3], [0.0; 3]);
    for (r, &a) in axes.iter().enumerate() {
        let t = h.string(&format!("CTYPE{a}")).unwrap_or_default();
        let u = h
            .string(&format!("CUNIT{a}"))
            .map(|u| u.trim().to_string())
            .filter(|u| !u.is_empty())
            .unwrap_or_else(|| default_unit(&t).to_string());
        ctype.push(t);
        unit.push(u);
        crpix[r] = num(format!("CRPIX{a}"), 0.0)?;
        crval[r] = num(format!("CRVAL{a}"), 0.0)?;
    }

    // M: CD if the header has any CDi_j, else CDELT · PC.
    let has_cd = h.cards.iter().any(|c| {
        c.key.strip_prefix("CD").is_some_and(|rest| {
            rest.split_once('_')
                .is_some_and(|(i, j)| i.parse::<u16>().is_ok() && j.parse::<u16>().is_ok())
        })
    });
    let mut notes = Vec::new();
    let mut m = [[0.0; 3]; 3];
    for (r, &a) in axes.iter().enumerate() {
        for (c, &b) in axes.iter().enumerate() {
            m[r][c] = if has_cd {
                num(format!("CD{a}_{b}"), 0.0)?
            } else {
                let cdelt = num(format!("CDELT{a}"), 1.0)?;
                cdelt * num(format!("PC{a}_{b}"), if a == b { 1.0 } else { 0.0 })?
            };
        }
    }
    if has_cd {
        notes.push("world steps from CDi_j (CDELTn and PCi_j, if any, not used)".to_string());
    }
    for c in 0..3 {
        if (0..3).all(|r| m[r][c] == 0.0) {
            let a = axes[c];
            return Err(format!(
                "{} gives NAXIS{a} a world step of 0",
                if has_cd {
                    format!("CD{a}_{a}")
                } else {
                    format!("CDELT{a} = {}", h.text(&format!("CDELT{a}")))
                }
            ));
        }
    }
    if let Some(rot) = h.float("CROTA2")?.filter(|&r| r != 0.0) {
        notes.push(format!(
            "CROTA2 = {rot} (the old rotation of the celestial axes) is not applied"
        ));
    }

    let names = ["x", "y", "z"];
    let describe = |r: usize| {
        let t = if ctype[r].is_empty() {
            "no CTYPE".to_string()
        } else {
            format!("'{}'", ctype[r])
        };
        let u = if unit[r].is_empty() {
            String::new()
        } else {
            format!(" ({})", unit[r])
        };
        format!("{} = NAXIS{} {t}{u}", names[r], axes[r])
    };
    let mut summary = format!("axes: {}, {}, {}", describe(0), describe(1), describe(2));
    if let Some(b) = h.string("BUNIT").filter(|b| !b.trim().is_empty()) {
        summary.push_str(&format!("; values in BUNIT '{}'", b.trim()));
    }
    notes.insert(0, summary);

    // World coordinates where the three axes are lengths (converted to
    // the finest of their units, as every reader does: shared/units.rs)
    // or angles (converted to the first axis's unit), or share one unit.
    let dims = unit.iter().map(|u| dimension(u)).collect::<Vec<_>>();
    let spatial = !ctype.iter().any(|t| is_spectral_or_other(t));
    let mut world_unit = unit[0].clone();
    let mut unit_notes = Vec::new();
    let scale = match (dims[0], dims[1], dims[2]) {
        (Dimension::Length(_), Dimension::Length(_), Dimension::Length(_)) => {
            let axis_names = axes.map(|a| format!("NAXIS{a}"));
            let lengths: Vec<AxisUnit> = (0..3)
                .map(|r| AxisUnit {
                    name: &axis_names[r],
                    unit: Some(&unit[r]),
                })
                .collect();
            let one = one_length_unit(&lengths);
            world_unit = one.length_unit.unwrap_or(world_unit);
            unit_notes = one.notes;
            Some([one.factors[0], one.factors[1], one.factors[2]])
        }
        (Dimension::Angle(a), Dimension::Angle(b), Dimension::Angle(c)) => {
            Some([1.0, b / a, c / a])
        }
        _ if unit[0] == unit[1] && unit[1] == unit[2] => Some([1.0; 3]),
        _ => None,
    }
    .filter(|_| spatial);

    let first = |r: usize| crval[r] + (0..3).map(|c| m[r][c] * (1.0 - crpix[c])).sum::<f64>();
    let Some(scale) = scale else {
        let axis_world = (0..3)
            .map(|r| {
                let u = if unit[r].is_empty() {
                    String::new()
                } else {
                    format!(" {}", unit[r])
                };
                let projected = if is_celestial(&ctype[r]) {
                    " (linear near the reference pixel)"
                } else {
                    ""
                };
                format!(
                    "{} from {}{u}, step {}{u}{projected}",
                    names[r],
                    first(r),
                    m[r][r]
                )
            })
            .collect::<Vec<_>>();
        notes.push(format!(
            "the axes are not one length ({}): rendered in FITS pixel coordinates (spacing 1, the first sample at 1), as ds9, SlicerAstro and yt lay out a spectral cube; world coordinates: {}",
            unit.iter()
                .zip(&ctype)
                .map(|(u, t)| if u.is_empty() { format!("'{t}'") } else { u.clone() })
                .collect::<Vec<_>>()
                .join(", "),
            axis_world.join("; ")
        ));
        return Ok(Geometry {
            steps: [DVec3::X, DVec3::Y, DVec3::Z],
            origin: DVec3::ONE,
            unit: Some("pixel".to_string()),
            notes,
        });
    };
    if !unit_notes.is_empty() {
        notes.extend(unit_notes);
    } else if scale != [1.0; 3] {
        notes.push(format!(
            "world coordinates converted to the unit of NAXIS{} ({}): {} and {} in other units",
            axes[0], unit[0], unit[1], unit[2]
        ));
    }
    let steps =
        [0, 1, 2].map(|c| DVec3::new(m[0][c] * scale[0], m[1][c] * scale[1], m[2][c] * scale[2]));
    let origin = DVec3::new(
        first(0) * scale[0],
        first(1) * scale[1],
        first(2) * scale[2],
    );
    Ok(Geometry {
        steps,
        origin,
        unit: (!world_unit.is_empty()).then_some(world_unit),
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::super::header::parse_card;
    use super::*;

    fn header(cards: &[&str]) -> Header {
        Header {
            cards: cards
                .iter()
                .map(|c| parse_card(&format!("{c:<80}")))
                .collect(),
        }
    }

    #[test]
    fn lengths_in_one_unit_are_world_coordinates() {
        let h = header(&[
            "CUNIT1  = 'mm'",
            "CUNIT2  = 'cm'",
            "CUNIT3  = 'mm'",
            "CDELT1  = 0.5",
            "CDELT2  = 0.1",
            "CRPIX1  = 3",
            "CRVAL1  = 10",
        ]);
        let g = geometry(&h, [1, 2, 3]).unwrap();
        assert_eq!(g.unit.as_deref(), Some("mm"));
        assert_eq!(g.steps[0], DVec3::new(0.5, 0.0, 0.0));
        assert!((g.steps[1].y - 1.0).abs() < 1e-12);
        // CRPIX 0 by default: sample 0 is pixel 1, one step past it.
        assert!((g.origin - DVec3::new(9.0, 1.0, 1.0)).length() < 1e-12);
        assert!(
            g.notes
                .contains(&"NAXIS1/NAXIS3 in mm, NAXIS2 in cm: spacing in mm (NAXIS2 × 10)".into()),
            "{:?}",
            g.notes
        );
        // The finest unit, whichever axis holds it: km, m, km in m.
        let h = header(&[
            "CUNIT1  = 'km'",
            "CUNIT2  = 'm'",
            "CUNIT3  = 'km'",
            "CDELT1  = 0.5",
        ]);
        let g = geometry(&h, [1, 2, 3]).unwrap();
        assert_eq!(g.unit.as_deref(), Some("m"));
        assert_eq!(g.steps[0], DVec3::new(500.0, 0.0, 0.0));
    }

    #[test]
    fn a_spectral_cube_is_rendered_in_pixels() {
        let h = header(&[
            "CTYPE1  = 'RA---SIN'",
            "CTYPE2  = 'DEC--SIN'",
            "CTYPE3  = 'VRAD'",
            "CDELT3  = 1000.0",
            "CRVAL3  = -5000.0",
            "CRPIX3  = 1.0",
        ]);
        let g = geometry(&h, [1, 2, 3]).unwrap();
        assert_eq!(g.unit.as_deref(), Some("pixel"));
        assert_eq!((g.steps[2], g.origin), (DVec3::Z, DVec3::ONE));
        let note = g
            .notes
            .iter()
            .find(|n| n.contains("pixel coordinates"))
            .unwrap();
        assert!(note.contains("z from -5000 m/s, step 1000 m/s"), "{note}");
        assert!(note.contains("deg, deg, m/s"), "{note}");
    }

    #[test]
    fn cd_matrices_and_zero_steps() {
        let h = header(&[
            "CD1_1   = 2.0",
            "CD2_2   = 3.0",
            "CD3_3   = 4.0",
            "CD1_2   = 1.0",
        ]);
        let g = geometry(&h, [1, 2, 3]).unwrap();
        assert_eq!(g.steps[1], DVec3::new(1.0, 3.0, 0.0));
        let h = header(&["CDELT2  = 0.0"]);
        let err = geometry(&h, [1, 2, 3]).err().unwrap();
        assert_eq!(err, "CDELT2 = 0.0 gives NAXIS2 a world step of 0");
    }
}
