//! How a file's regions encode their samples ([`Encoding`]), and the
//! sample type and encoding all of them share ([`Layout`]).

use volray_core::SampleType;

use crate::dtype::{DType, Endian};

/// How a region's bytes encode the samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Encoding {
    /// The samples' bytes as they are.
    Raw,
    /// gzip (RFC 1952), possibly several concatenated members.
    Gzip,
    /// zlib (RFC 1950), or gzip where the stream starts with gzip's magic
    /// (MetaIO inflates with `inflateInit2(.., 47)`, which accepts both).
    Zlib,
    /// bzip2, possibly several concatenated streams (NRRD `encoding: bzip2`,
    /// written by teem with libbz2's `BZ2_bzWrite`).
    Bzip2,
    /// Decimal numbers separated by whitespace or commas.
    Text,
    /// Two hexadecimal digits per byte, whitespace between them ignored.
    Hex,
}

impl Encoding {
    pub(crate) fn is_compressed(self) -> bool {
        matches!(self, Encoding::Gzip | Encoding::Zlib | Encoding::Bzip2)
    }
}

/// The sample type and encoding shared by all regions of a file.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Layout {
    pub dtype: DType,
    pub endian: Endian,
    pub encoding: Encoding,
    /// Bytes of the inflated stream to skip before the samples (NRRD
    /// `byte skip` with a compressed encoding).
    pub inflated_skip: u64,
}

impl Layout {
    /// The type the volume keeps: the file's own ([`DType::stored`]), or
    /// `f32` for numbers written as text.
    pub(crate) fn stored(&self) -> SampleType {
        match self.encoding {
            Encoding::Text => SampleType::F32,
            _ => self.dtype.stored(),
        }
    }
}
