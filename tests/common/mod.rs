//! Running the `volray` binary from the integration tests.
#![allow(dead_code)] // each test binary uses part of this

use std::fs;
use std::path::Path;
use std::process::{Command, Output};

/// Runs `volray` with `args` and returns what it did.
pub fn volray(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_volray"))
        .args(args)
        .output()
        .expect("volray runs")
}

pub fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// An 8-bit RGB picture read back from a PNG volray wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct Picture {
    pub width: usize,
    pub height: usize,
    /// Row 0 at the top, x fastest.
    pub rgb: Vec<[u8; 3]>,
}

impl Picture {
    pub fn read(path: &Path) -> Picture {
        let decoder = png::Decoder::new(std::io::BufReader::new(fs::File::open(path).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!(info.color_type, png::ColorType::Rgb);
        assert_eq!(info.bit_depth, png::BitDepth::Eight);
        Picture {
            width: info.width as usize,
            height: info.height as usize,
            rgb: buf[..info.buffer_size()]
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect(),
        }
    }

    pub fn at(&self, col: usize, row: usize) -> [u8; 3] {
        self.rgb[col + self.width * row]
    }

    /// The largest channel difference from `other`, of the same size.
    pub fn max_diff(&self, other: &Picture) -> u8 {
        assert_eq!((self.width, self.height), (other.width, other.height));
        (self.rgb.iter().zip(&other.rgb))
            .flat_map(|(a, b)| (0..3).map(move |c| a[c].abs_diff(b[c])))
            .max()
            .unwrap()
    }
}
