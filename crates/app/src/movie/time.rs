//! A fractional time point shown blended (the keyframes file's `"time":
//! "interpolate"`): `(1 − w)·a + w·b` voxel by voxel, in `f32`, on `a`'s
//! grid. The two time points of one file share their grid; two that do
//! not are refused.

use volray_core::Volume;

/// The volume `w` of the way from `a` to `b`.
pub fn blend(a: &Volume, b: &Volume, w: f64) -> Result<Volume, String> {
    if a.dims() != b.dims() {
        return Err(format!(
            "time points of {:?} and {:?} voxels cannot be blended",
            a.dims(),
            b.dims()
        ));
    }
    let (va, vb) = (a.values(), b.values());
    let w = w as f32;
    let data = (va.iter().zip(vb.iter()))
        .map(|(&x, &y)| x + (y - x) * w)
        .collect();
    let out = Volume::new(a.dims(), data)
        .and_then(|v| v.with_spacing(a.spacing()))
        .and_then(|v| v.with_origin(a.origin()))
        .map_err(|e| e.to_string())?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blending_mixes_each_voxel_linearly() {
        let a = Volume::new([2, 2, 2], vec![0.0, 10.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
        let b = Volume::new([2, 2, 2], vec![4.0, 20.0, 4.0, 4.0, 4.0, 4.0, 4.0, 4.0]).unwrap();
        let m = blend(&a, &b, 0.25).unwrap();
        assert_eq!(&m.values()[..2], &[1.0, 12.5]);
        let c = Volume::new([2, 2, 3], vec![0.0; 12]).unwrap();
        assert!(blend(&a, &c, 0.5).is_err());
    }
}
