//! Writing a [`Volume`] as an attached NRRD file: samples in the volume's
//! own type (`uint8`, `int8`, `uint16`, `int16`, `float`), raw
//! little-endian, in a 3-D space whose `space directions` and `space
//! origin` carry the volume's spacing and origin exactly.

use std::path::Path;

use volray_core::{SampleType, Volume};

use crate::atomic::write_atomically;
use crate::error::IoError;

/// Samples per write.
const CHUNK: usize = 1 << 16;

/// The NRRD `type` of samples of type `t` (teem's spellings).
fn nrrd_type(t: SampleType) -> &'static str {
    match t {
        SampleType::U8 => "uint8",
        SampleType::I8 => "int8",
        SampleType::U16 => "uint16",
        SampleType::I16 => "int16",
        SampleType::F32 => "float",
    }
}

/// Writes `volume` to `path` as a NRRD file (format version 4, attached
/// data), atomically: a failed write leaves no partial file.
///
/// The header says `space dimension: 3` (volray's world has no anatomical
/// meaning), `space directions` `(dx,0,0) (0,dy,0) (0,0,dz)` and `space
/// origin` with every number written so it reads back to the same `f64`.
/// teem, ITK, 3D Slicer and pynrrd read the file as written.
///
/// ```
/// use volray_core::{Volume, glam::DVec3};
/// use volray_io::{ReadOptions, read, write_nrrd};
///
/// let dir = tempfile::tempdir()?;
/// let path = dir.path().join("v.nrrd");
/// let v = Volume::from_fn([3, 2, 2], DVec3::new(0.5, 1.0, 2.0), DVec3::new(1.0, 2.0, 3.0), |p| p.x as f32)?;
/// write_nrrd(&path, &v)?;
/// assert_eq!(read(&path, &ReadOptions::default())?.volume, v);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn write_nrrd(path: &Path, volume: &Volume) -> Result<(), IoError> {
    let [nx, ny, nz] = volume.dims();
    let s = volume.spacing();
    let o = volume.origin();
    // `{:?}` writes the shortest text that parses back to the same f64.
    let header = format!(
        "NRRD0004\n\
         # Complete NRRD file format specification at:\n\
         # http://teem.sourceforge.net/nrrd/format.html\n\
         # written by volray\n\
         type: {}\n\
         dimension: 3\n\
         space dimension: 3\n\
         sizes: {nx} {ny} {nz}\n\
         space directions: ({:?},0,0) (0,{:?},0) (0,0,{:?})\n\
         kinds: domain domain domain\n\
         endian: little\n\
         encoding: raw\n\
         space origin: ({:?},{:?},{:?})\n\
         \n",
        nrrd_type(volume.sample_type()),
        s.x,
        s.y,
        s.z,
        o.x,
        o.y,
        o.z
    );
    write_atomically(path, |w| {
        w.write_all(header.as_bytes())?;
        volume
            .samples()
            .try_for_each_le_chunk(CHUNK, |bytes| w.write_all(bytes))?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ReadOptions, read};
    use volray_core::glam::DVec3;

    #[test]
    fn round_trip_keeps_values_and_geometry_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rt.nrrd");
        let spacing = DVec3::new(0.1, 1.0 / 3.0, 2e-7);
        let origin = DVec3::new(-1.5e10, 0.0, std::f64::consts::PI);
        let v = Volume::from_fn([4, 3, 2], spacing, origin, |p| {
            (p.x * 1e-9 + p.y * 7.0 - p.z) as f32
        })
        .unwrap();
        write_nrrd(&path, &v).unwrap();
        let loaded = read(&path, &ReadOptions::default()).unwrap();
        assert_eq!(loaded.volume, v);
        assert_eq!(loaded.info.stored_type, "float (f32, little-endian)");
        assert!(loaded.info.notes.is_empty(), "{:?}", loaded.info.notes);
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(
            bytes.len() - 24 * 4,
            bytes.windows(2).position(|w| w == b"\n\n").unwrap() + 2
        );
    }

    #[test]
    fn failed_write_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let v = Volume::new([2, 2, 2], vec![0.0; 8]).unwrap();
        let err = write_nrrd(&dir.path().join("no/such/dir/v.nrrd"), &v).unwrap_err();
        assert!(err.is_io_failure());
        assert!(!dir.path().join("no").exists());
    }
}
