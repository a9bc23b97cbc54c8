//! The samples behind a text header (NRRD, MetaImage): one or more data
//! regions (the rest of the header's own file, or separate data files),
//! each raw, gzip-, zlib- or bzip2-compressed, decimal text or hexadecimal, turned
//! into `f32` with one frame of a multi-volume file kept.
//!
//! A header is trusted only as far as the files bear it out:
//! [`Region::locate`] finds where each region's data starts and how many
//! bytes follow, [`check_region`] compares that with what the header
//! declares before anything is allocated, and [`read_regions`] reads no
//! byte past a region. Compressed streams cannot be sized from the file,
//! so their declared size is bounded by the codec's largest ratio and the
//! output grows only as data actually inflates; a stream that inflates to
//! less or more than declared is refused.
//!
//! [`read_regions`]: read::read_regions

mod decode;
mod frame;
mod layout;
mod numbered;
mod read;
mod region;
#[cfg(test)]
mod tests;

pub(crate) use self::frame::FrameSelect;
pub(crate) use self::layout::{Encoding, Layout};
pub(crate) use self::numbered::{MAX_FILES, format_number, number_range};
pub(crate) use self::read::plan_frame;
pub(crate) use self::region::{Region, Skip, check_region};
