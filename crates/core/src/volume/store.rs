//! Where a volume's samples live: in a vector the volume owns, or in bytes
//! something else owns, such as a file mapped into memory (a volume larger
//! than the memory it may take is read that way, its pages brought in by
//! the operating system as the renderer touches them, and dropped again
//! under pressure: they are the file's, not the process's).
//!
//! Either way a path sees `&[T]`: [`Store`] dereferences to the slice, so
//! the loops written over [`Sample`] slices read a mapped file as they read
//! memory. What an owner of outside bytes adds is [`ExternalBytes::verify`]:
//! a file can be truncated or rewritten under a mapping, and the renderer
//! asks, after each frame, whether the bytes it read were still the file's
//! (see [`crate::Render::render`]).

use std::fmt;
use std::marker::PhantomData;
use std::ops::Deref;
use std::sync::Arc;

use super::sample::Sample;

/// Bytes owned outside the volume, in native byte order: a mapped file.
pub trait ExternalBytes: Send + Sync + fmt::Debug {
    /// All of them, the same slice at every call; a volume's samples are
    /// a range of these.
    fn bytes(&self) -> &[u8];

    /// `Ok` if the bytes are still what they were when the volume was
    /// made; otherwise why not (a file truncated or rewritten while it was
    /// mapped), for the error the renderer returns.
    fn verify(&self) -> Result<(), String>;
}

/// A volume's samples of type `T`.
#[derive(Clone)]
pub enum Store<T> {
    /// In a vector of the volume's own.
    Owned(Vec<T>),
    /// `len` samples from byte `offset` of an owner's bytes.
    External(External<T>),
}

/// Samples in bytes owned elsewhere, checked once (bounds and alignment)
/// when made, so that reading them never fails.
#[derive(Clone)]
pub struct External<T> {
    owner: Arc<dyn ExternalBytes>,
    offset: usize,
    len: usize,
    _type: PhantomData<T>,
}

/// Why outside bytes cannot hold a volume's samples.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ExternalError {
    #[error(
        "{len} samples of {size} bytes from byte {offset} run past the {available} bytes there are"
    )]
    OutOfBounds {
        offset: usize,
        len: usize,
        size: usize,
        available: usize,
    },
    #[error(
        "samples of {size} bytes cannot start at byte {offset}: not a multiple of {size} from an aligned start"
    )]
    Misaligned { offset: usize, size: usize },
}

impl<T: Sample> External<T> {
    /// The `len` samples of `T` from byte `offset` of `owner`'s bytes,
    /// refused unless they lie within them and are aligned for `T` in
    /// memory.
    pub fn new(
        owner: Arc<dyn ExternalBytes>,
        offset: usize,
        len: usize,
    ) -> Result<Self, ExternalError> {
        let size = size_of::<T>();
        let bytes = owner.bytes();
        let end = len
            .checked_mul(size)
            .and_then(|n| n.checked_add(offset))
            .filter(|&end| end <= bytes.len())
            .ok_or(ExternalError::OutOfBounds {
                offset,
                len,
                size,
                available: bytes.len(),
            })?;
        let start = bytes[offset..end].as_ptr() as usize;
        if !start.is_multiple_of(align_of::<T>()) {
            return Err(ExternalError::Misaligned { offset, size });
        }
        Ok(External {
            owner,
            offset,
            len,
            _type: PhantomData,
        })
    }

    /// The owner's answer to [`ExternalBytes::verify`].
    pub fn verify(&self) -> Result<(), String> {
        self.owner.verify()
    }
}

impl<T: Sample> Deref for Store<T> {
    type Target = [T];

    #[inline]
    fn deref(&self) -> &[T] {
        match self {
            Store::Owned(v) => v,
            Store::External(e) => {
                let bytes = &e.owner.bytes()[e.offset..e.offset + e.len * size_of::<T>()];
                // Bounds and alignment were checked in `External::new`
                // (the owner gives the same bytes each time).
                bytemuck::cast_slice(bytes)
            }
        }
    }
}

impl<T> From<Vec<T>> for Store<T> {
    fn from(v: Vec<T>) -> Self {
        Store::Owned(v)
    }
}

impl<T: Sample> PartialEq for Store<T> {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

impl<T: Sample + fmt::Debug> fmt::Debug for Store<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Store::Owned(v) => f.debug_tuple("Owned").field(v).finish(),
            Store::External(e) => f
                .debug_struct("External")
                .field("owner", &e.owner)
                .field("offset", &e.offset)
                .field("len", &e.len)
                .finish(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug)]
    struct Bytes(Vec<u8>, bool);

    impl ExternalBytes for Bytes {
        fn bytes(&self) -> &[u8] {
            &self.0
        }
        fn verify(&self) -> Result<(), String> {
            if self.1 {
                Ok(())
            } else {
                Err("changed".into())
            }
        }
    }

    #[test]
    fn outside_bytes_read_as_the_samples_they_hold() {
        let values: [u16; 4] = [1, 300, 65535, 7];
        let mut raw = vec![0u8; 2];
        raw.extend(values.iter().flat_map(|v| v.to_ne_bytes()));
        let owner: Arc<dyn ExternalBytes> = Arc::new(Bytes(raw, true));
        let e = External::<u16>::new(owner.clone(), 2, 4).unwrap();
        let store = Store::External(e.clone());
        assert_eq!(&*store, &values);
        assert_eq!(store, Store::Owned(values.to_vec()));
        assert_eq!(e.verify(), Ok(()));
        assert!(matches!(
            External::<u16>::new(owner.clone(), 2, 5),
            Err(ExternalError::OutOfBounds { available: 10, .. })
        ));
        assert!(matches!(
            External::<u16>::new(owner.clone(), usize::MAX, 1),
            Err(ExternalError::OutOfBounds { .. })
        ));
        // A Vec<u8>'s buffer is at least 2-aligned in practice, so byte 1 is not.
        if (owner.bytes().as_ptr() as usize).is_multiple_of(2) {
            assert!(matches!(
                External::<u16>::new(owner, 1, 2),
                Err(ExternalError::Misaligned { offset: 1, size: 2 })
            ));
        }
        let changed: Arc<dyn ExternalBytes> = Arc::new(Bytes(vec![0; 4], false));
        let e = External::<f32>::new(changed, 0, 1).unwrap();
        assert_eq!(e.verify(), Err("changed".to_string()));
    }
}
