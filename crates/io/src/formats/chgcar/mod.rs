//! VASP volumetric files: CHGCAR and CHG (charge density), and the files
//! written the same way (AECCAR0/1/2, PARCHG, LOCPOT, ELFCAR), read with
//! volray's own parser (<https://www.vasp.at/wiki/index.php/CHGCAR>).
//!
//! ```text
//! POSCAR block           system, scale, lattice, species, counts, positions (see poscar.rs)
//! (blank line)
//! NGX NGY NGZ
//! values                 x fastest, then y, then z: 5 per line (CHGCAR), 10 (CHG)
//! [augmentation occupancies ...]        CHGCAR only, skipped
//! [NGX NGY NGZ + values + ...]           more blocks: magnetisation of a spin-polarised
//!                                        run (1 block), or m_x, m_y, m_z (non-collinear, 3)
//! [next POSCAR block ...]                CHG: one image per stored ionic step
//! ```
//!
//! Choices, each stated in [`FileInfo::notes`]:
//!
//! - Charge files store ρ·V_cell; values are divided by the cell volume
//!   (VASP wiki, CHGCAR), giving electrons per Å³. LOCPOT (a potential,
//!   eV) and ELFCAR (the dimensionless ELF) are not scaled.
//! - Frames are the density blocks in file order: `--frame 0` the total
//!   density (default), 1 the magnetisation (spin-polarised runs), 1 to 3
//!   its x, y, z parts (non-collinear runs); in a CHG file with several
//!   ionic steps the next step's blocks follow.
//! - The grid is periodic: point i sits at i/NGX along lattice vector a
//!   and point NGX would repeat point 0. On an orthogonal lattice the
//!   volume gets that wrap-around plane appended on each axis (NG + 1
//!   points) so it spans the whole cell; on a skewed lattice the cell is
//!   resampled onto an orthogonal grid covering its bounding box (see
//!   [`crate::shared::periodic_cell`]).
//! - Lengths in ångström; the origin of the cell is the world origin.

mod poscar;

pub(crate) use poscar::sniff_text;

use std::path::Path;

use volray_core::glam::DVec3;

use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::limits::{check_held, format_bytes};
use crate::shared::packed::open_unpacked;
use crate::shared::periodic_cell;
use crate::shared::text_reader::{TextReader, number, parse_number};
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

/// What a VASP file's values are, from its name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Content {
    /// CHGCAR, CHG, AECCAR*, PARCHG, and unknown names: ρ·V_cell.
    ChargeTimesVolume,
    /// LOCPOT or ELFCAR: stored as they are.
    Unscaled(&'static str),
}

fn content_of(path: &Path) -> Content {
    // Any word of the name: `LOCPOT`, `Li_LOCPOT`, `run3-ELFCAR.gz`.
    let words = name_words(path);
    if words.iter().any(|w| w == "locpot") {
        Content::Unscaled("LOCPOT holds the local potential in eV")
    } else if words.iter().any(|w| w == "elfcar") {
        Content::Unscaled("ELFCAR holds the dimensionless electron localisation function")
    } else {
        Content::ChargeTimesVolume
    }
}

/// Whether `path`'s name says which VASP file it is (a word of it is
/// one of the names the format table lists).
fn named(path: &Path) -> bool {
    let stems = VolumeFormat::Chgcar.spec().name_stems;
    name_words(path).iter().any(|w| stems.contains(&w.as_str()))
}

/// The words of `path`'s file name, lower case, split at `.`, `_`, `-`.
fn name_words(path: &Path) -> Vec<String> {
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    name.split(['.', '_', '-']).map(str::to_string).collect()
}

/// The block of the file that was read, once found.
struct Chosen {
    image: usize,
    block: usize,
    poscar: poscar::Poscar,
    grid_fields: Vec<String>,
    ng: [usize; 3],
    data: Vec<f32>,
}

/// Reads the VASP volumetric file at `path` (see the module docs).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let opened = open_unpacked(path)?;
    let packed_note = opened.note();
    let file_len = opened.len;
    let mut r = TextReader::new(path, opened.reader);
    let content = content_of(path);
    let wanted = opts.frame.unwrap_or(0);

    let mut chosen: Option<Chosen> = None;
    // Blocks per image, in file order.
    let mut blocks_per_image: Vec<usize> = Vec::new();
    let mut frames = 0usize;
    let mut next_image = Some(r.line("the system name")?);

    while let Some(system) = next_image.take() {
        let image = blocks_per_image.len();
        let poscar = poscar::read(&mut r, system, file_len)?;
        let (ng, grid_fields) = poscar::read_grid_line(&mut r, file_len)?;
        let count = ng[0] * ng[1] * ng[2];
        let mut blocks = 0;
        loop {
            let what = format!("density block {}", frames + 1);
            if frames == wanted {
                let p = poscar.clone();
                let scale = match content {
                    Content::ChargeTimesVolume => 1.0 / p.volume,
                    Content::Unscaled(_) => 1.0,
                };
                // The block, and a copy with the periodic planes added.
                let closed = ng.iter().map(|&n| n as u128 + 1).product::<u128>();
                let peak = (count as u128 + closed) * 4;
                check_held(
                    path,
                    &format!("NGX NGY NGZ {} {} {}", ng[0], ng[1], ng[2]),
                    count as u128,
                    peak,
                    &format!(
                        "{} as f32 with the closed periodic copy",
                        format_bytes(peak)
                    ),
                    opts.max_memory,
                )?;
                let mut data = Vec::with_capacity(count);
                r.tokens(count, &what, |_, t| {
                    data.push((number(t, "grid value")? * scale) as f32);
                    Ok(())
                })?;
                chosen = Some(Chosen {
                    image,
                    block: blocks,
                    poscar: p,
                    grid_fields: grid_fields.clone(),
                    ng,
                    data,
                });
            } else {
                r.tokens(count, &what, |_, _| Ok(()))?;
            }
            r.finish_line(&format!("the {count} values of {what}"))?;
            frames += 1;
            blocks += 1;

            // What follows: the grid line again (another block of this
            // image), augmentation occupancies and other numbers (skipped),
            // a new image's system name, or the end of the file.
            let mut another_block = false;
            while let Some(line) = r.try_line()? {
                let tokens: Vec<&str> = line.split_whitespace().collect();
                if tokens == grid_fields {
                    another_block = true;
                    break;
                }
                let numeric = tokens.iter().all(|t| parse_number(t).is_some());
                if numeric || line.trim_start().starts_with("augmentation") {
                    continue;
                }
                next_image = Some(line);
                break;
            }
            if !another_block {
                break;
            }
        }
        blocks_per_image.push(blocks);
    }

    let Some(chosen) = chosen else {
        return Err(IoError::frame_out_of_range(
            path,
            wanted,
            format!(
                "the file holds {frames} density block(s) (frames 0 to {})",
                frames - 1
            ),
        ));
    };

    let mut info = FileInfo::new("decimal text");
    info.notes.extend(packed_note);
    info.header = chosen.poscar.header;
    info.header
        .push(("NGX NGY NGZ".into(), chosen.grid_fields.join(" ")));
    info.length_unit = Some("angstrom".into());
    info.frames = frames;
    info.frame = wanted;
    let in_image = blocks_per_image[chosen.image];
    let label = match (content, in_image, chosen.block) {
        (Content::Unscaled(_), n, b) if n > 1 => format!("block {} of {n}", b + 1),
        (Content::Unscaled(_), _, _) | (_, 1, _) => "the only block".to_string(),
        (_, 2, 0) | (_, 4, 0) => "the total density (spin up + spin down)".to_string(),
        (_, 2, 1) => "the magnetisation density (spin up - spin down)".to_string(),
        (_, 4, b) => format!(
            "the magnetisation density m_{} (non-collinear)",
            ["x", "y", "z"][b - 1]
        ),
        (_, n, b) => format!("block {} of {n}", b + 1),
    };
    let images = blocks_per_image.len();
    info.notes.push(if images > 1 {
        format!(
            "frame {wanted} of {frames} is {label} of ionic step {} of the {images} stored in the file",
            chosen.image + 1
        )
    } else {
        format!("frame {wanted} of {frames} is {label}")
    });
    if !named(path) {
        info.notes.push(
            "known as VASP by its content: the name says not which file it is, so it is read as a charge file (CHGCAR, CHG, AECCAR, PARCHG); a LOCPOT or ELFCAR, whose values are not divided by the cell volume, is known by a name holding LOCPOT or ELFCAR".into(),
        );
    }
    match content {
        Content::ChargeTimesVolume => info.notes.push(format!(
            "values divided by the cell volume {:.6} cubic angstrom (the file stores density times volume, as the VASP wiki documents for CHGCAR): electrons per cubic angstrom",
            chosen.poscar.volume
        )),
        Content::Unscaled(what) => info
            .notes
            .push(format!("values as stored, not divided by the cell volume: {what}")),
    }

    let ng = chosen.ng;
    let lattice = chosen.poscar.lattice;
    let steps = [
        lattice[0] / ng[0] as f64,
        lattice[1] / ng[1] as f64,
        lattice[2] / ng[2] as f64,
    ];
    let volume = if periodic_cell::is_skewed(steps) {
        let (volume, note) = periodic_cell::resample(
            ng,
            &chosen.data,
            steps,
            DVec3::ZERO,
            ["a", "b", "c"],
            "angstrom",
            opts.max_memory,
        )
        .map_err(|e| e.at(path, "lattice"))?;
        info.notes.push(note);
        volume
    } else {
        info.notes.push(format!(
            "the grid is periodic (point NG repeats point 0): the wrap-around plane was appended on each axis, so the volume's {} x {} x {} points span the whole cell",
            ng[0] + 1,
            ng[1] + 1,
            ng[2] + 1
        ));
        let closed = close_periodic(ng, &chosen.data);
        let dims = [ng[0] + 1, ng[1] + 1, ng[2] + 1];
        grid_to_volume(path, dims, closed, steps, DVec3::ZERO, &mut info)?
    };
    Ok(Loaded {
        volume,
        format: VolumeFormat::Chgcar,
        info,
    })
}

/// The periodic grid `data` (`ng` points, x fastest) with the plane of
/// index `ng[a]` (a copy of plane 0) appended on each axis.
fn close_periodic(ng: [usize; 3], data: &[f32]) -> Vec<f32> {
    let [nx, ny, nz] = ng;
    let mut out = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
    for k in 0..=nz {
        for j in 0..=ny {
            let row = nx * ((j % ny) + ny * (k % nz));
            out.extend_from_slice(&data[row..row + nx]);
            out.push(data[row]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closing_a_periodic_grid_repeats_plane_zero() {
        let data: Vec<f32> = (0..24).map(|v| v as f32).collect();
        let out = close_periodic([2, 3, 4], &data);
        assert_eq!(out.len(), 3 * 4 * 5);
        let at = |i: usize, j: usize, k: usize| out[i + 3 * (j + 4 * k)];
        for k in 0..5 {
            for j in 0..4 {
                for i in 0..3 {
                    let src = (i % 2) + 2 * ((j % 3) + 3 * (k % 4));
                    assert_eq!(at(i, j, k), src as f32, "({i}, {j}, {k})");
                }
            }
        }
    }

    #[test]
    fn content_follows_the_name() {
        assert_eq!(
            content_of(Path::new("run/CHGCAR")),
            Content::ChargeTimesVolume
        );
        assert_eq!(content_of(Path::new("AECCAR2")), Content::ChargeTimesVolume);
        assert!(matches!(
            content_of(Path::new("LOCPOT.gz")),
            Content::Unscaled(_)
        ));
        assert!(matches!(
            content_of(Path::new("x/ELFCAR_spin")),
            Content::Unscaled(_)
        ));
        assert_eq!(
            content_of(Path::new("density.vasp")),
            Content::ChargeTimesVolume
        );
    }
}
