//! A volume's samples in the type they were stored in: 8- and 16-bit
//! integers stay 1 and 2 bytes a voxel in memory (a 1024³ 16-bit CT is
//! 2 GiB, not the 4 GiB of an `f32` copy).
//!
//! Every path reads a sample as the `f32` it converts to exactly
//! ([`Sample::to_f32`]: every `u8`, `i8`, `u16` and `i16` is an `f32`), at
//! the moment it reads it, and computes from there in `f32` as before; so
//! a volume of any of these types renders exactly as its `f32` conversion
//! would, bit for bit. The loops that read samples are written once,
//! generic over [`Sample`], and [`with_samples!`](crate::with_samples)
//! picks the instance for a volume's type once per call, outside the loop.

use super::sample::{Sample, SampleType};
use super::store::Store;

/// A volume's samples, x fastest, in their stored type, in memory or in
/// bytes owned elsewhere ([`Store`]).
#[derive(Debug, Clone, PartialEq)]
pub enum Samples {
    U8(Store<u8>),
    I8(Store<i8>),
    U16(Store<u16>),
    I16(Store<i16>),
    F32(Store<f32>),
}

/// Runs `$body` with `$data` bound to the samples of `$samples` (a
/// [`Samples`]) as a slice of their own type: the body is compiled once
/// per sample type, so that a loop inside it reads its type directly.
#[macro_export]
macro_rules! with_samples {
    ($samples:expr, |$data:ident| $body:expr) => {
        match $samples {
            $crate::Samples::U8(v) => {
                let $data: &[u8] = &**v;
                $body
            }
            $crate::Samples::I8(v) => {
                let $data: &[i8] = &**v;
                $body
            }
            $crate::Samples::U16(v) => {
                let $data: &[u16] = &**v;
                $body
            }
            $crate::Samples::I16(v) => {
                let $data: &[i16] = &**v;
                $body
            }
            $crate::Samples::F32(v) => {
                let $data: &[f32] = &**v;
                $body
            }
        }
    };
}

impl Samples {
    /// Number of samples.
    pub fn len(&self) -> usize {
        with_samples!(self, |data| data.len())
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Their type.
    pub fn sample_type(&self) -> SampleType {
        match self {
            Samples::U8(_) => SampleType::U8,
            Samples::I8(_) => SampleType::I8,
            Samples::U16(_) => SampleType::U16,
            Samples::I16(_) => SampleType::I16,
            Samples::F32(_) => SampleType::F32,
        }
    }

    /// Sample `i` as `f32`.
    #[inline]
    pub fn get(&self, i: usize) -> f32 {
        with_samples!(self, |data| data[i].to_f32())
    }

    /// `Ok` for samples in memory; for samples in outside bytes (a mapped
    /// file), whether those are still what they were
    /// ([`ExternalBytes::verify`](super::ExternalBytes::verify)).
    pub fn verify(&self) -> Result<(), String> {
        fn of<T: Sample>(store: &Store<T>) -> Result<(), String> {
            match store {
                Store::Owned(_) => Ok(()),
                Store::External(e) => e.verify(),
            }
        }
        match self {
            Samples::U8(s) => of(s),
            Samples::I8(s) => of(s),
            Samples::U16(s) => of(s),
            Samples::I16(s) => of(s),
            Samples::F32(s) => of(s),
        }
    }

    /// Whether the samples are in outside bytes (a mapped file) rather
    /// than in memory the volume owns.
    pub fn is_external(&self) -> bool {
        matches!(
            self,
            Samples::U8(Store::External(_))
                | Samples::I8(Store::External(_))
                | Samples::U16(Store::External(_))
                | Samples::I16(Store::External(_))
                | Samples::F32(Store::External(_))
        )
    }

    /// Every sample as `f32`, in a new vector.
    pub fn to_f32_vec(&self) -> Vec<f32> {
        with_samples!(self, |data| data.iter().map(|v| v.to_f32()).collect())
    }

    /// Passes the samples to `f` as `f32`, in order, `chunk` at a time (the
    /// last chunk may be shorter), converting through one scratch buffer
    /// rather than a copy of them all; stops at `f`'s first error.
    pub fn try_for_each_f32_chunk<E>(
        &self,
        chunk: usize,
        mut f: impl FnMut(&[f32]) -> Result<(), E>,
    ) -> Result<(), E> {
        let chunk = chunk.max(1);
        if let Samples::F32(data) = self {
            return data.chunks(chunk).try_for_each(f);
        }
        let mut scratch = Vec::with_capacity(chunk);
        with_samples!(self, |data| {
            data.chunks(chunk).try_for_each(|c| {
                scratch.clear();
                scratch.extend(c.iter().map(|v| v.to_f32()));
                f(&scratch)
            })
        })
    }
}

impl Samples {
    /// Passes the samples to `f` as little-endian bytes of their own type,
    /// in order, `chunk` samples at a time (the last chunk may be
    /// shorter): the bytes a file stores them as. On a little-endian
    /// machine these are the samples' own bytes, no copy; elsewhere each
    /// chunk is swapped through one scratch buffer. Stops at `f`'s first
    /// error.
    pub fn try_for_each_le_chunk<E>(
        &self,
        chunk: usize,
        mut f: impl FnMut(&[u8]) -> Result<(), E>,
    ) -> Result<(), E> {
        let chunk = chunk.max(1);
        let mut scratch: Vec<u8> = Vec::new();
        with_samples!(self, |data| {
            data.chunks(chunk).try_for_each(|c| {
                let bytes: &[u8] = bytemuck::cast_slice(c);
                if cfg!(target_endian = "little") {
                    return f(bytes);
                }
                let size = std::mem::size_of_val(&c[0]);
                scratch.clear();
                scratch.extend(bytes.chunks_exact(size).flat_map(|b| b.iter().rev()));
                f(&scratch)
            })
        })
    }
}

impl From<Vec<f32>> for Samples {
    fn from(v: Vec<f32>) -> Self {
        Samples::F32(Store::Owned(v))
    }
}

impl From<Vec<u8>> for Samples {
    fn from(v: Vec<u8>) -> Self {
        Samples::U8(Store::Owned(v))
    }
}

impl From<Vec<i8>> for Samples {
    fn from(v: Vec<i8>) -> Self {
        Samples::I8(Store::Owned(v))
    }
}

impl From<Vec<u16>> for Samples {
    fn from(v: Vec<u16>) -> Self {
        Samples::U16(Store::Owned(v))
    }
}

impl From<Vec<i16>> for Samples {
    fn from(v: Vec<i16>) -> Self {
        Samples::I16(Store::Owned(v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_integer_sample_converts_to_f32_exactly() {
        for v in [i16::MIN, -1, 0, 1, i16::MAX] {
            assert_eq!(v.to_f32() as i16, v);
        }
        for v in [0, 1, 32768, u16::MAX] {
            assert_eq!(v.to_f32() as u16, v);
        }
        // u16 needs 16 bits of mantissa; f32 has 24.
        assert_eq!(65535u16.to_f32(), 65535.0);
        assert_eq!((-128i8).to_f32(), -128.0);
        assert_eq!(255u8.to_f32(), 255.0);
        assert!(!f32::NAN.is_finite() && Sample::is_finite(7u8));
    }

    #[test]
    fn samples_pass_as_little_endian_bytes_of_their_own_type() {
        let mut out = Vec::new();
        let s = Samples::from(vec![0x0102u16, 0xfffe, 7]);
        s.try_for_each_le_chunk(2, |b| {
            out.push(b.to_vec());
            Ok::<(), ()>(())
        })
        .unwrap();
        assert_eq!(out, vec![vec![2, 1, 0xfe, 0xff], vec![7, 0]]);
        let mut all = Vec::new();
        Samples::from(vec![1.5f32, -2.0])
            .try_for_each_le_chunk(8, |b| {
                all.extend_from_slice(b);
                Ok::<(), ()>(())
            })
            .unwrap();
        let expect: Vec<u8> = [1.5f32, -2.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        assert_eq!(all, expect);
        let err = Samples::from(vec![1i8, 2, 3])
            .try_for_each_le_chunk(1, |b| if b == [2] { Err("stop") } else { Ok(()) });
        assert_eq!(err, Err("stop"));
    }

    #[test]
    fn samples_report_their_type_and_values() {
        let s = Samples::from(vec![3u16, 65535, 0]);
        assert_eq!((s.sample_type(), s.len()), (SampleType::U16, 3));
        assert_eq!(s.get(1), 65535.0);
        assert_eq!(s.to_f32_vec(), vec![3.0, 65535.0, 0.0]);
        let mut chunks = Vec::new();
        let done: Result<(), ()> = s.try_for_each_f32_chunk(2, |c| {
            chunks.push(c.to_vec());
            Ok(())
        });
        assert_eq!(done, Ok(()));
        assert_eq!(chunks, [vec![3.0, 65535.0], vec![0.0]]);
        assert_eq!(SampleType::U16.bytes(), 2);
        assert_eq!(SampleType::I8.name(), "i8");
    }
}
