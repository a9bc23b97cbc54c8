//! CCP4 / MRC maps (`.map`, `.mrc`, `.ccp4`): electron density maps of
//! crystallography and cryo-electron microscopy, read with volray's own
//! parser of the MRC2014 header (Cheng et al., J. Struct. Biol. 192, 146,
//! 2015; <https://www.ccpem.ac.uk/mrc-format/mrc2014/>).
//!
//! A 1024-byte header of 56 four-byte words and ten 80-byte labels, an
//! extended header of NSYMBT bytes, then NX·NY·NZ samples: columns
//! fastest, then rows, then sections. What volray takes from the header:
//!
//! - MODE: 0 int8 (unsigned bytes in IMOD files without the "signed" flag,
//!   the convention before IMOD 4.2.23), 1 int16, 2 float32, 6 uint16,
//!   12 float16; complex modes 3 and 4, 4-bit mode 101 and others are
//!   refused.
//! - Byte order from MACHST (`44 44` or `44 41` little, `11 11` big); a
//!   stamp that is missing or contradicts MODE is overruled by the byte
//!   order in which MODE and the sizes make sense, with a note.
//! - Voxel size along crystal axis X, Y, Z: cell length / MX, MY, MZ (Å).
//! - MAPC, MAPR, MAPS: which crystal axis the columns, rows and sections
//!   run along; `grid_to_volume` permutes the samples so x is fastest.
//! - Origin (MRC2014 and UCSF Chimera's reading): ORIGIN (Å) when it is
//!   not zero, else NCSTART, NRSTART, NSSTART times the voxel size (the
//!   CCP4 convention); the note says which was used.
//! - Cell angles other than 90°: a map covering exactly one unit cell is
//!   periodic and is resampled onto an orthogonal grid (see
//!   [`crate::shared::periodic_cell`]); a map of a part of a skewed cell,
//!   or of more than one cell, is not: its own box (a parallelepiped) is
//!   resampled onto an axis-aligned grid at its finest spacing, and the
//!   samples outside the box are NaN, marked as empty space
//!   ([`FileInfo::nan_is_empty`]).

use std::io::{Seek, SeekFrom};
use std::path::Path;

use volray_core::glam::DVec3;

use crate::dtype::{DType, Endian, Stored, read_as_stored};
use crate::error::IoError;
use crate::shared::geometry::grid_to_volume;
use crate::shared::input::{open_input, read_exact_at, read_samples};
use crate::shared::limits::check_dims;
use crate::shared::mapped::{self, Plan};
use crate::shared::periodic_cell;
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

/// Length of the main header.
const HEADER_LEN: usize = 1024;

/// IMOD's stamp at byte 152: the word after it holds IMOD's bit flags.
const IMOD_STAMP: i32 = 1_146_047_817;
/// IMOD flag: mode 0 bytes are signed (unsigned without it).
const IMOD_SIGNED_BYTES: i32 = 1;
/// IMOD flag: ORIGIN is stored with its sign inverted.
const IMOD_ORIGIN_INVERTED: i32 = 4;

/// Angles within this many degrees of 90 count as right angles (headers
/// hold single-precision floats).
const ANGLE_TOLERANCE: f64 = 1e-3;

/// The main header's bytes and the byte order they are read in.
struct Header {
    bytes: [u8; HEADER_LEN],
    endian: Endian,
}

impl Header {
    /// The 4 bytes of 1-based word `w`.
    fn word(&self, w: usize) -> [u8; 4] {
        let at = 4 * (w - 1);
        [
            self.bytes[at],
            self.bytes[at + 1],
            self.bytes[at + 2],
            self.bytes[at + 3],
        ]
    }

    fn int(&self, w: usize) -> i32 {
        match self.endian {
            Endian::Little => i32::from_le_bytes(self.word(w)),
            Endian::Big => i32::from_be_bytes(self.word(w)),
        }
    }

    fn float(&self, w: usize) -> f32 {
        match self.endian {
            Endian::Little => f32::from_le_bytes(self.word(w)),
            Endian::Big => f32::from_be_bytes(self.word(w)),
        }
    }

    fn ints<const N: usize>(&self, first: usize) -> [i32; N] {
        std::array::from_fn(|i| self.int(first + i))
    }

    fn floats<const N: usize>(&self, first: usize) -> [f32; N] {
        std::array::from_fn(|i| self.float(first + i))
    }

    /// True if MODE is one MRC defines and NX, NY, NZ are positive in this
    /// byte order: how a header shows its byte order when MACHST does not.
    fn plausible(&self) -> bool {
        matches!(self.int(4), 0 | 1 | 2 | 3 | 4 | 6 | 12 | 16 | 101)
            && self.ints::<3>(1).iter().all(|&n| n > 0 && n < (1 << 24))
    }
}

/// The other byte order.
fn opposite(e: Endian) -> Endian {
    match e {
        Endian::Little => Endian::Big,
        Endian::Big => Endian::Little,
    }
}

/// Four header bytes as text if printable, else as hex.
fn show_bytes(b: &[u8]) -> String {
    if b.iter().all(|c| c.is_ascii_graphic() || *c == b' ') {
        format!("'{}'", String::from_utf8_lossy(b))
    } else {
        b.iter()
            .map(|c| format!("{c:02x}"))
            .collect::<Vec<_>>()
            .join(" ")
    }
}

/// Reads the CCP4/MRC map at `path` (see the module docs).
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let invalid = |reason: String| IoError::invalid(path, reason);
    let (mut file, file_len) = open_input(path)?;
    if file_len < HEADER_LEN as u64 {
        return Err(invalid(format!(
            "file is {file_len} bytes, shorter than the {HEADER_LEN}-byte MRC header"
        )));
    }
    let mut bytes = [0u8; HEADER_LEN];
    read_exact_at(path, &mut file, &mut bytes, 0, HEADER_LEN as u64)?;
    let mut notes = Vec::new();

    // Byte order: MACHST, checked against MODE and the sizes.
    let machst = [bytes[212], bytes[213], bytes[214], bytes[215]];
    let stamped = match machst {
        [0x44, 0x44 | 0x41, ..] => Some(Endian::Little),
        [0x11, 0x11, ..] => Some(Endian::Big),
        _ => None,
    };
    // MRC2014 asks for "MAP " and permits "MAP" followed by a NUL.
    let map_stamp = bytes[208..211] == *b"MAP";
    let plausible = |endian| Header { bytes, endian }.plausible();
    let endian = match stamped {
        Some(e) if plausible(e) || !plausible(opposite(e)) => e,
        Some(e) => {
            notes.push(format!(
                "MACHST {} says {e}-endian, but MODE and NX, NY, NZ only make sense {}-endian: read {}-endian",
                show_bytes(&machst),
                opposite(e),
                opposite(e)
            ));
            opposite(e)
        }
        None => {
            let e = if !plausible(Endian::Little) && plausible(Endian::Big) {
                Endian::Big
            } else {
                Endian::Little
            };
            notes.push(format!(
                "MACHST {} is not a known machine stamp: read {e}-endian{}",
                show_bytes(&machst),
                if plausible(e) {
                    ", in which MODE and NX, NY, NZ make sense"
                } else {
                    " (in neither byte order do MODE and NX, NY, NZ make sense)"
                }
            ));
            e
        }
    };
    let h = Header { bytes, endian };

    // The header's fields, as written.
    let dims_i = h.ints::<3>(1);
    let mode = h.int(4);
    let nstart = h.ints::<3>(5);
    let m = h.ints::<3>(8);
    let cell = h.floats::<3>(11);
    let angles = h.floats::<3>(14);
    let map = h.ints::<3>(17);
    let stats = h.floats::<3>(20);
    let ispg = h.int(23);
    let nsymbt = h.int(24);
    let exttyp = &h.bytes[104..108];
    let nversion = h.int(28);
    let imod_stamp = h.int(39);
    let imod_flags = h.int(40);
    let origin_field = h.floats::<3>(50);
    let rms = h.float(55);
    let nlabl = h.int(56);

    let join3 = |v: &[String]| v.join(" ");
    let mut header: Vec<(String, String)> = Vec::new();
    let mut put = |k: &str, v: String| header.push((k.to_string(), v));
    put("NX NY NZ", join3(&dims_i.map(|v| v.to_string())));
    put("MODE", mode.to_string());
    put(
        "NXSTART NYSTART NZSTART",
        join3(&nstart.map(|v| v.to_string())),
    );
    put("MX MY MZ", join3(&m.map(|v| v.to_string())));
    put("CELLA", join3(&cell.map(|v| v.to_string())));
    put("CELLB", join3(&angles.map(|v| v.to_string())));
    put("MAPC MAPR MAPS", join3(&map.map(|v| v.to_string())));
    put("DMIN DMAX DMEAN", join3(&stats.map(|v| v.to_string())));
    put("ISPG", ispg.to_string());
    put("NSYMBT", nsymbt.to_string());
    put("EXTTYP", show_bytes(exttyp));
    put("NVERSION", nversion.to_string());
    let imod = imod_stamp == IMOD_STAMP;
    if imod {
        put("imodStamp", imod_stamp.to_string());
        put("imodFlags", imod_flags.to_string());
    }
    put("ORIGIN", join3(&origin_field.map(|v| v.to_string())));
    put("MAP", show_bytes(&h.bytes[208..212]));
    put("MACHST", show_bytes(&machst));
    put("RMS", rms.to_string());
    put("NLABL", nlabl.to_string());
    for i in 0..nlabl.clamp(0, 10) as usize {
        let raw = &h.bytes[224 + 80 * i..224 + 80 * (i + 1)];
        let text = String::from_utf8_lossy(raw);
        put(
            &format!("LABEL {}", i + 1),
            text.trim_end_matches(['\0', ' ']).to_string(),
        );
    }
    if !map_stamp {
        notes.push(format!(
            "no 'MAP ' stamp at byte 208 ({} there): an old-style header, whose ORIGIN words are not trusted",
            show_bytes(&h.bytes[208..212])
        ));
    }

    // Sample type.
    let (dtype, type_name) = match mode {
        0 if imod && imod_flags & IMOD_SIGNED_BYTES == 0 => {
            notes.push(
                "MODE 0 read as unsigned bytes: an IMOD file (imodStamp) without the signed-bytes flag in imodFlags, IMOD's convention before version 4.2.23".into(),
            );
            (DType::U8, "uint8")
        }
        0 => (DType::I8, "int8"),
        1 => (DType::I16, "int16"),
        2 => (DType::F32, "float32"),
        6 => (DType::U16, "uint16"),
        12 => (DType::F16, "float16"),
        3 | 4 => {
            return Err(invalid(format!(
                "MODE {mode}: complex (Fourier transform) data; volray renders real-space maps (modes 0, 1, 2, 6, 12)"
            )));
        }
        101 => {
            return Err(invalid(
                "MODE 101: 4-bit samples packed two per byte are not supported (modes 0, 1, 2, 6, 12 are)".into(),
            ));
        }
        _ => {
            return Err(invalid(format!(
                "MODE {mode}: not a real-valued MRC mode volray reads (0 int8, 1 int16, 2 float32, 6 uint16, 12 float16)"
            )));
        }
    };

    // Sizes, checked against the file before anything is allocated.
    if let Some(n) = dims_i.iter().find(|&&n| n <= 0) {
        return Err(invalid(format!(
            "NX NY NZ are {} {} {}: {n} is not a size",
            dims_i[0], dims_i[1], dims_i[2]
        )));
    }
    if nsymbt < 0 {
        return Err(invalid(format!(
            "NSYMBT {nsymbt}: the extended header cannot have a negative size"
        )));
    }
    let dims = dims_i.map(|n| n as usize);
    // Three sizes below 2^31 and 8-byte samples cannot overflow u128.
    let count = dims[0] as u128 * dims[1] as u128 * dims[2] as u128;
    let data_bytes = count * dtype.size() as u128;
    let offset = HEADER_LEN as u64 + nsymbt as u64;
    let end = offset as u128 + data_bytes;
    if (file_len as u128) < end {
        return Err(invalid(format!(
            "NX NY NZ {} {} {} of MODE {mode} ({} bytes each) need {data_bytes} bytes after the {offset}-byte header{}, but the file is {file_len} bytes",
            dims[0],
            dims[1],
            dims[2],
            dtype.size(),
            if nsymbt > 0 {
                format!(" (with NSYMBT {nsymbt})")
            } else {
                String::new()
            }
        )));
    }
    // The file holds the data, so these sizes fit in u64 and usize.
    let end = end as u64;
    let kept = dtype.stored().bytes() as u64;
    // Over the limit, the map may still be mapped (decided below).
    let within_limit = match check_dims(path, "NX NY NZ", &dims, kept, opts.max_memory) {
        Err(e) if !matches!(e, IoError::OverMemoryLimit { .. }) => return Err(e),
        other => other,
    };
    let count = count as usize;
    if file_len > end {
        notes.push(format!("{} bytes after the data ignored", file_len - end));
    }
    if nsymbt > 0 {
        notes.push(format!(
            "extended header of {nsymbt} bytes (EXTTYP {}) skipped",
            show_bytes(exttyp)
        ));
    }
    if (401..=630).contains(&ispg) {
        notes.push(format!(
            "ISPG {ispg} marks a stack of volumes: read as one volume of {} sections",
            dims[2]
        ));
    }

    // Axes: which crystal axis (0 X, 1 Y, 2 Z) columns, rows and sections run along.
    let axis_of = if map == [0, 0, 0] {
        notes.push("MAPC MAPR MAPS are 0 0 0: read as 1 2 3 (columns along X)".into());
        [0, 1, 2]
    } else {
        let mut sorted = map;
        sorted.sort_unstable();
        if sorted != [1, 2, 3] {
            return Err(invalid(format!(
                "MAPC MAPR MAPS are {} {} {}: not an order of the axes 1, 2, 3",
                map[0], map[1], map[2]
            )));
        }
        map.map(|a| (a - 1) as usize)
    };

    // Voxel size along X, Y, Z.
    let mut voxel = DVec3::ONE;
    let names = ["X", "Y", "Z"];
    for a in 0..3 {
        let (c, n) = (f64::from(cell[a]), m[a]);
        if !c.is_finite() {
            return Err(invalid(format!(
                "CELLA {} {} {}: the cell length along {} is not finite",
                cell[0], cell[1], cell[2], names[a]
            )));
        }
        // A cell of 0 (unset, common in tomography) gives no voxel size:
        // 1 angstrom, as UCSF Chimera uses.
        if c > 0.0 && n > 0 {
            voxel[a] = c / f64::from(n);
        } else {
            notes.push(format!(
                "cell length {c} over M{} {n} gives no voxel size along {}: 1 angstrom used",
                names[a], names[a]
            ));
        }
    }

    // The unit cell's axes: orthogonal, or skewed by the cell angles.
    let mut deg = angles.map(f64::from);
    if deg == [0.0; 3] {
        notes.push("CELLB is 0 0 0: read as 90 90 90".into());
        deg = [90.0; 3];
    }
    if let Some(a) = deg
        .iter()
        .find(|a| !(a.is_finite() && **a > 0.0 && **a < 180.0))
    {
        return Err(invalid(format!(
            "CELLB {} {} {}: the angle {a} cannot be a cell angle",
            deg[0], deg[1], deg[2]
        )));
    }
    let skewed = deg.iter().any(|a| (a - 90.0).abs() > ANGLE_TOLERANCE);
    let axes = if skewed {
        cell_axes(deg)
    } else {
        [DVec3::X, DVec3::Y, DVec3::Z]
    };
    let crystal_steps = [axes[0] * voxel.x, axes[1] * voxel.y, axes[2] * voxel.z];
    let steps = axis_of.map(|a| crystal_steps[a]);
    if axis_of != [0, 1, 2] {
        notes.push(format!(
            "columns, rows and sections run along {}, {}, {} (MAPC MAPR MAPS)",
            names[axis_of[0]], names[axis_of[1]], names[axis_of[2]]
        ));
    }

    // Origin: ORIGIN if set, else NxSTART in voxels.
    let mut origin_xyz = DVec3::new(
        f64::from(origin_field[0]),
        f64::from(origin_field[1]),
        f64::from(origin_field[2]),
    );
    if map_stamp && !origin_xyz.is_finite() {
        return Err(invalid(format!(
            "ORIGIN {} {} {} is not finite",
            origin_field[0], origin_field[1], origin_field[2]
        )));
    }
    let use_origin_field = map_stamp && origin_xyz != DVec3::ZERO;
    let origin = if use_origin_field {
        if imod && imod_flags & IMOD_ORIGIN_INVERTED != 0 {
            origin_xyz = -origin_xyz;
            notes.push("imodFlags says ORIGIN is stored with its sign inverted: negated".into());
        }
        let note = if nstart != [0, 0, 0] {
            format!(
                "origin from ORIGIN ({}, {}, {}) angstrom; NXSTART NYSTART NZSTART {} {} {} not added (ORIGIN takes precedence, as in MRC2014 readers such as UCSF Chimera)",
                origin_xyz.x, origin_xyz.y, origin_xyz.z, nstart[0], nstart[1], nstart[2]
            )
        } else {
            format!(
                "origin from ORIGIN ({}, {}, {}) angstrom",
                origin_xyz.x, origin_xyz.y, origin_xyz.z
            )
        };
        notes.push(note);
        origin_xyz
    } else {
        let origin = (0..3).fold(DVec3::ZERO, |o, d| o + steps[d] * f64::from(nstart[d]));
        if nstart != [0, 0, 0] {
            notes.push(format!(
                "origin from NCSTART NRSTART NSSTART {} {} {} times the voxel size: ({}, {}, {}) angstrom",
                nstart[0], nstart[1], nstart[2], origin.x, origin.y, origin.z
            ));
        }
        origin
    };

    // The samples, streamed: column fastest.
    file.seek(SeekFrom::Start(offset))
        .map_err(|e| IoError::os(path, "seek in", e))?;
    let endian = h.endian;
    let mappable = if skewed {
        Err("a skewed cell is resampled as it is read".to_string())
    } else {
        mapped::mappable(dtype, endian, offset)
    };
    let plan = mapped::plan(opts.map, mappable, within_limit)?;
    let data = if plan == Plan::Map {
        mapped::map_samples(path, offset, dtype, count)?
    } else {
        read_as_stored!(dtype.stored(), |T| {
            let mut data: Vec<T> = Vec::with_capacity(count);
            read_samples(
                path,
                &mut file,
                count,
                dtype.size(),
                offset,
                |bytes, out| T::extend(out, bytes, dtype, endian),
                |values| data.extend_from_slice(values),
            )
            .map(|()| data)
        })?
    };

    let mut info = FileInfo::new(format!("{type_name} (MODE {mode}, {endian}-endian)"));
    info.header = header;
    info.length_unit = Some("angstrom".into());
    // A skewed grid one point thick is an image: grid_to_volume says so.
    let volume = if skewed && dims.iter().all(|&n| n >= 2) {
        let whole_cell = (0..3).all(|d| m[axis_of[d]] as i64 == dims[d] as i64);
        let resample = if whole_cell {
            periodic_cell::resample
        } else {
            // A part of the cell, or more than one: the map's own box.
            info.nan_is_empty = true;
            notes.push(format!(
                "the map's {} x {} x {} points are not the whole cell's MX MY MZ {} {} {} (in column, row, section order): not periodic, so only its own box is resampled",
                dims[0], dims[1], dims[2], m[axis_of[0]], m[axis_of[1]], m[axis_of[2]]
            ));
            periodic_cell::resample_box
        };
        let axis_names = axis_of.map(|a| names[a]);
        let (volume, note) = resample(
            dims,
            &data.to_f32_vec(),
            steps,
            origin,
            axis_names,
            "angstrom",
            opts.max_memory,
        )
        .map_err(|e| e.at(path, "CELLB"))?;
        notes.push(note);
        volume
    } else {
        grid_to_volume(path, dims, data, steps, origin, &mut info)?
    };
    if plan == Plan::Map {
        notes.push(mapped::mapped_note(&volume));
    }
    // Notes in the order the header was read, then geometry's own.
    let geometry_notes = std::mem::take(&mut info.notes);
    info.notes = notes;
    info.notes.extend(geometry_notes);
    Ok(Loaded {
        volume,
        format: VolumeFormat::Mrc,
        info,
    })
}

/// Unit vectors of the crystal axes a, b, c for cell angles α, β, γ
/// (degrees), in the standard orthogonalisation (a along x, b in the xy
/// plane; International Tables for Crystallography Vol. B, 3.3.1.1.1).
fn cell_axes(deg: [f64; 3]) -> [DVec3; 3] {
    let [alpha, beta, gamma] = deg.map(f64::to_radians);
    let (ca, cb, cg, sg) = (alpha.cos(), beta.cos(), gamma.cos(), gamma.sin());
    let cy = (ca - cb * cg) / sg;
    let cz = (1.0 - cb * cb - cy * cy).max(0.0).sqrt();
    [DVec3::X, DVec3::new(cg, sg, 0.0), DVec3::new(cb, cy, cz)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cell_axes_meet_at_the_cell_angles() {
        let axes = cell_axes([80.0, 100.0, 115.0]);
        let angle = |u: DVec3, v: DVec3| u.dot(v).acos().to_degrees();
        for v in axes {
            assert!((v.length() - 1.0).abs() < 1e-12);
        }
        assert!((angle(axes[1], axes[2]) - 80.0).abs() < 1e-9);
        assert!((angle(axes[0], axes[2]) - 100.0).abs() < 1e-9);
        assert!((angle(axes[0], axes[1]) - 115.0).abs() < 1e-9);
    }

    #[test]
    fn byte_order_shows_in_plausible_headers() {
        let mut bytes = [0u8; HEADER_LEN];
        for (w, v) in [(1, 4i32), (2, 3), (3, 5), (4, 2)] {
            bytes[4 * (w - 1)..4 * w].copy_from_slice(&v.to_be_bytes());
        }
        let be = Header {
            bytes,
            endian: Endian::Big,
        };
        let le = Header {
            bytes,
            endian: Endian::Little,
        };
        assert!(be.plausible());
        assert!(!le.plausible());
        assert_eq!(be.ints::<3>(1), [4, 3, 5]);
        assert_eq!(show_bytes(b"MAP "), "'MAP '");
        assert_eq!(show_bytes(&[0x44, 0x41, 0, 0]), "44 41 00 00");
    }
}
