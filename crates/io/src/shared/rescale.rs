//! Stored values rescaled to the values they mean, `value = slope·stored +
//! intercept` (NIfTI's `scl_slope`/`scl_inter`, DICOM's RescaleSlope and
//! RescaleIntercept), kept in an integer type when they allow it.
//!
//! A CT series stores 12 bits unsigned with intercept −1024: every value is
//! an integer from −1024 to 3071, which `i16` holds exactly, so the volume
//! takes 2 bytes a voxel instead of the 4 of `f32`, and renders bit for bit
//! as the `f32` values would (each integer is its own `f32`). Where the
//! slope or the intercept is not an integer, or the values outside every
//! 16-bit type, they are `f32`: `(slope·stored + intercept) as f32`, the
//! arithmetic in `f64`, as the readers always did.

use volray_core::{Sample, SampleType, Samples, with_samples};

use crate::dtype::{Stored, read_as_stored};

/// Integers beyond this are not rescaled in an integer type (their
/// products could leave the integers `f64` holds exactly).
const EXACT: f64 = (1u64 << 40) as f64;

/// The narrowest of `u8`, `i8`, `u16`, `i16` that holds every integer from
/// `lo` to `hi`, or `None`.
pub(crate) fn integer_type(lo: f64, hi: f64) -> Option<SampleType> {
    [
        (SampleType::U8, 0.0, 255.0),
        (SampleType::I8, -128.0, 127.0),
        (SampleType::U16, 0.0, 65535.0),
        (SampleType::I16, -32768.0, 32767.0),
    ]
    .into_iter()
    .find(|&(_, min, max)| lo >= min && hi <= max)
    .map(|(t, _, _)| t)
}

/// The range of `slope·v + intercept` for integers `v` from `lo` to `hi`,
/// if slope and intercept are integers (and everything stays exact).
pub(crate) fn rescaled_range(lo: f64, hi: f64, slope: f64, intercept: f64) -> Option<(f64, f64)> {
    let integer = |x: f64| x.is_finite() && x.fract() == 0.0 && x.abs() < EXACT;
    // An intercept of −0 can give −0, which no integer type holds.
    let minus_zero = intercept == 0.0 && intercept.is_sign_negative();
    if minus_zero || !(integer(slope) && integer(intercept) && integer(lo) && integer(hi)) {
        return None;
    }
    let (a, b) = (slope * lo + intercept, slope * hi + intercept);
    Some((a.min(b), a.max(b)))
}

/// `samples` rescaled: in the narrowest integer type holding every value
/// where [`rescaled_range`] and [`integer_type`] find one for the values
/// present, as `f32` otherwise. `slope == 1, intercept == 0` keeps them.
pub(crate) fn rescale(samples: Samples, slope: f64, intercept: f64) -> Samples {
    if slope == 1.0 && intercept == 0.0 {
        return samples;
    }
    let range = with_samples!(&samples, |data| value_range(data));
    let kept = range
        .and_then(|(lo, hi)| rescaled_range(lo, hi, slope, intercept))
        .and_then(|(lo, hi)| integer_type(lo, hi))
        .unwrap_or(SampleType::F32);
    let done: Result<Samples, std::convert::Infallible> = read_as_stored!(kept, |T| Ok(
        with_samples!(&samples, |data| apply::<_, T>(data, slope, intercept))
    ));
    match done {
        Ok(s) => s,
    }
}

/// Smallest and largest value (`None` for none, or for a NaN among them).
fn value_range<S: Sample>(data: &[S]) -> Option<(f64, f64)> {
    let mut it = data.iter().map(|v| f64::from(v.to_f32()));
    let first = it.next()?;
    let (mut lo, mut hi) = (first, first);
    for v in it {
        if v.is_nan() {
            return None;
        }
        lo = lo.min(v);
        hi = hi.max(v);
    }
    (!first.is_nan()).then_some((lo, hi))
}

/// `slope·v + intercept` of each sample, in `f64`, stored as `T` (a type
/// that holds every result exactly, or `f32`: rounded once).
fn apply<S: Sample, T: Stored>(data: &[S], slope: f64, intercept: f64) -> Vec<T> {
    data.iter()
        .map(|v| T::from_f64(slope * f64::from(v.to_f32()) + intercept))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integer_types_are_the_narrowest_that_hold_the_range() {
        assert_eq!(integer_type(0.0, 255.0), Some(SampleType::U8));
        assert_eq!(integer_type(-1.0, 127.0), Some(SampleType::I8));
        assert_eq!(integer_type(-1.0, 128.0), Some(SampleType::I16));
        assert_eq!(integer_type(0.0, 65535.0), Some(SampleType::U16));
        assert_eq!(integer_type(-1024.0, 3071.0), Some(SampleType::I16));
        assert_eq!(integer_type(-1024.0, 64511.0), None);
        assert_eq!(
            rescaled_range(0.0, 4095.0, 1.0, -1024.0),
            Some((-1024.0, 3071.0))
        );
        assert_eq!(rescaled_range(0.0, 10.0, -2.0, 5.0), Some((-15.0, 5.0)));
        assert_eq!(rescaled_range(0.0, 10.0, 0.5, 0.0), None);
        assert_eq!(rescaled_range(0.0, 10.0, 1.0, 0.25), None);
    }

    /// Whatever type the rescaled values land in, they are the `f32`s the
    /// f64 arithmetic gives, bit for bit.
    #[test]
    fn rescaled_values_are_the_f32_arithmetic_in_the_narrowest_type() {
        let ct: Vec<u16> = vec![0, 1, 1024, 2000, 4095];
        let cases: [(Samples, f64, f64, SampleType); 6] = [
            (Samples::from(ct.clone()), 1.0, -1024.0, SampleType::I16),
            (Samples::from(ct.clone()), 1.0, 0.0, SampleType::U16),
            (Samples::from(ct.clone()), 2.0, 0.0, SampleType::U16),
            (Samples::from(ct.clone()), 0.5, -1024.0, SampleType::F32),
            (Samples::from(vec![-3i8, 0, 7]), -1.0, 100.0, SampleType::U8),
            (Samples::from(vec![0u16, 65535]), 1.0, -1.0, SampleType::F32),
        ];
        for (samples, slope, intercept, want) in cases {
            let expect: Vec<f32> = (samples.to_f32_vec().iter())
                .map(|&v| (slope * f64::from(v) + intercept) as f32)
                .collect();
            let got = rescale(samples, slope, intercept);
            assert_eq!(got.sample_type(), want, "{slope} {intercept}");
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got.to_f32_vec()), bits(&expect));
        }
        let floats = Samples::from(vec![1.5, f32::NAN]);
        let got = rescale(floats, 2.0, 1.0).to_f32_vec();
        assert_eq!(got[0], 4.0);
        assert!(got[1].is_nan());
    }
}
