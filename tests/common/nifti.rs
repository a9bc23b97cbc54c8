//! 4-D NIfTI-1 files of 24³ frames written byte by byte (a 348-byte
//! header, float32, unit spacing from `pixdim`): channels or time points
//! along dim[4], for the tests of several volumes in one picture.

use std::path::Path;

pub const N: usize = 24;

/// A 24³ frame: `f(x, y, z)` at each point, x fastest.
pub fn frame(f: impl Fn(f64, f64, f64) -> f32) -> Vec<f32> {
    let mut out = Vec::with_capacity(N * N * N);
    for z in 0..N {
        for y in 0..N {
            for x in 0..N {
                out.push(f(x as f64, y as f64, z as f64));
            }
        }
    }
    out
}

/// A soft ball of radius 6 about (12, `y`, 12): 1 at its centre, 0 outside.
pub fn ball(y: f64) -> Vec<f32> {
    frame(|px, py, pz| {
        let r = ((px - 12.0).powi(2) + (py - y).powi(2) + (pz - 12.0).powi(2)).sqrt();
        (1.0 - r / 6.0).max(0.0) as f32
    })
}

/// A NIfTI-1 file (`.nii`, float32, unit spacing) holding `frames` of
/// 24³ along dim[4].
pub fn nifti(dir: &Path, name: &str, frames: &[Vec<f32>]) -> String {
    let mut header = vec![0u8; 352];
    let put_i16 =
        |h: &mut Vec<u8>, at: usize, v: i16| h[at..at + 2].copy_from_slice(&v.to_le_bytes());
    let put_f32 =
        |h: &mut Vec<u8>, at: usize, v: f32| h[at..at + 4].copy_from_slice(&v.to_le_bytes());
    header[0..4].copy_from_slice(&348i32.to_le_bytes());
    let n = N as i16;
    let dims = [4, n, n, n, frames.len() as i16, 1, 1, 1];
    for (i, d) in dims.iter().enumerate() {
        put_i16(&mut header, 40 + 2 * i, *d);
    }
    put_i16(&mut header, 70, 16); // float32
    put_i16(&mut header, 72, 32);
    for (i, p) in [1.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0].iter().enumerate() {
        put_f32(&mut header, 76 + 4 * i, *p);
    }
    put_f32(&mut header, 108, 352.0); // vox_offset
    put_f32(&mut header, 112, 1.0); // scl_slope
    header[123] = 2; // mm
    header[344..348].copy_from_slice(b"n+1\0");
    for f in frames {
        assert_eq!(f.len(), N * N * N);
        header.extend(f.iter().flat_map(|v| v.to_le_bytes()));
    }
    let path = dir.join(name);
    std::fs::write(&path, header).unwrap();
    path.to_str().unwrap().to_string()
}
