//! Every input the fuzzers (`fuzz/`, docs/robustness.md) found a reader
//! mishandling, minimised, read again: each must now be refused with a
//! clean, one-line error naming the file and the problem, not a panic, a
//! hang or a huge allocation. The inputs live in
//! `tests/fixtures/fuzz/<target>/`; each test says what went wrong before.

use std::path::{Path, PathBuf};

use volray_io::{ReadOptions, VolumeFormat, read};

/// `tests/fixtures/fuzz/<target>/<name>`.
fn finding(target: &str, name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/fuzz")
        .join(target)
        .join(name)
}

/// Reads `path` as `format` (with `frame`, `array`) and returns the error
/// message, checking that it is a bad-input error, one line, starting
/// with the file.
fn refusal(path: &Path, format: VolumeFormat, frame: Option<usize>, array: Option<&str>) -> String {
    let opts = ReadOptions {
        format: Some(format),
        frame,
        array: array.map(str::to_string),
        ..ReadOptions::default()
    };
    let err = match read(path, &opts) {
        Ok(loaded) => panic!(
            "{}: read as {:?}, expected a refusal",
            path.display(),
            loaded.volume.dims()
        ),
        Err(err) => err,
    };
    let message = err.to_string();
    assert!(!err.is_io_failure(), "{message}");
    assert!(!message.contains('\n'), "{message}");
    assert!(
        message.starts_with(&path.display().to_string()),
        "{message}"
    );
    message
}

/// A 859-byte DICOM file whose Modality (0008,0060) claims VR FD (8-byte
/// floats) with a 2-byte value. `dicom-parser` reads 0 doubles, moves on
/// by 2 bytes without consuming them, and so takes the next element's
/// value bytes for a header declaring 1 766 195 214 bytes, which it
/// allocated: out of memory under libFuzzer's 1 GB limit. The pre-scan
/// now refuses binary-VR lengths that are not a multiple of the value size.
#[test]
fn dicom_binary_vr_length_not_a_multiple_of_its_value_size() {
    let path = finding("dicom", "fd_length_not_multiple.dcm");
    let message = refusal(&path, VolumeFormat::Dicom, None, None);
    assert!(
        message.contains("(0008,0060)") && message.contains("not a multiple of 8"),
        "{message}"
    );
}

/// A 710-byte DICOM file in Deflated Explicit VR Little Endian whose data
/// set holds (7FE0,0002) (VR bytes 00 00, so a 32-bit length) declaring
/// 1 224 757 008 bytes before the pixel data. The pre-scan stopped at the
/// first element of group 7FE0 and left it unchecked, but the header
/// parse reads up to (7FE0,0008) and, the data set being deflated, is
/// not cut short where the pre-scan stopped: it allocated 1.2 GB. The
/// pre-scan now stops where the parse does.
#[test]
fn dicom_deflated_element_before_pixel_data_is_checked() {
    let path = finding("dicom", "deflated_7fe0_0002_huge.dcm");
    let message = refusal(&path, VolumeFormat::Dicom, None, None);
    assert!(
        message.contains("(7FE0,0002)") && message.contains("declares 1224757008 bytes"),
        "{message}"
    );
}

/// A 1094-byte DICOM file in JPEG-LS Lossless (a CharLS-encoded 16 x 12
/// frame) whose scan header (SOS) declares a length of 65535 bytes, far
/// past the frame's end. The decoder sliced the stream at that offset
/// unchecked: a panic, caught, but printed with a backtrace before the
/// one-line error (issue 41). The decoder now refuses the length.
#[test]
fn dicom_jpegls_scan_header_length_past_the_stream() {
    let path = finding("dicom", "jpegls_sos_length_past_end.dcm");
    let message = refusal(&path, VolumeFormat::Dicom, None, None);
    assert!(
        message.contains("JPEG-LS") && message.contains("past the stream's end"),
        "{message}"
    );
}

/// A 950-byte DICOM file in RLE Lossless (16 x 12, 16 bits) whose RLE
/// header's first 12 bytes are garbled: 1 515 870 810 segments, offsets
/// to match. `dicom-pixeldata` trusted the header and allocated 6 GB (an
/// abort under `ulimit -v`, found by tests/hostile_files.rs; other
/// segment counts made it panic). Each fragment's RLE header is now
/// checked first (issue 41).
#[test]
fn dicom_rle_header_with_a_garbled_segment_count() {
    let path = finding("dicom", "rle_header_garbled.dcm");
    let message = refusal(&path, VolumeFormat::Dicom, None, None);
    assert!(
        message.contains("declares 1515870810 RLE segment(s)"),
        "{message}"
    );
}
