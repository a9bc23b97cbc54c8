//! A JPEG-LS decoder (ITU-T T.87 | ISO/IEC 14495-1), lossless and
//! near-lossless, for one greyscale component: what DICOM's JPEG-LS
//! transfer syntaxes (1.2.840.10008.1.2.4.80 and .81) hold.
//!
//! Why here: the only JPEG-LS decoder on crates.io is `charls`, bindings to
//! the C++ CharLS, which builds with CMake and a C++ compiler — set-up the
//! README's two commands do not do. The algorithm (LOCO-I) is small:
//! context modelling of three local gradients (A.3), median edge
//! prediction with a bias correction per context (A.4), Golomb-coded
//! residuals with adaptive parameters (A.5, A.6), and a run mode for flat
//! areas (A.7). Section numbers are those of T.87 (06/98). The decoder
//! follows CharLS's reading of the standard where the text is terse (the
//! line borders, the run interruption error mapping), and is checked
//! against CharLS-encoded files (tests/dicom_codecs.rs).
//!
//! Not read: several components or interleaved scans (DICOM greyscale has
//! one), mapping tables (LSE IDs 2 and 3), point transform (Al > 0).
//! Every read is bounds-checked, so corrupt input is an error, not a panic.

/// Decodes the JPEG-LS stream `stream` of one component into its samples,
/// row by row. `max_samples` bounds the image (the caller has checked the
/// frame header against the DICOM header already).
pub(super) fn decode(stream: &[u8], max_samples: usize) -> Result<Vec<u16>, String> {
    let h = parse(stream)?;
    if h.width.saturating_mul(h.height) > max_samples {
        return Err(format!("{}x{} is larger than the image", h.width, h.height));
    }
    // SOS's length field places the scan data; a corrupt one points past
    // the stream.
    let data = stream.get(h.scan..).ok_or_else(|| {
        format!(
            "the scan header's length puts the scan data at byte {}, past the stream's end ({} bytes)",
            h.scan,
            stream.len()
        )
    })?;
    let mut d = Decoder::new(&h, data)?;
    d.run()
}

/// Frame and scan parameters.
struct Header {
    width: usize,
    height: usize,
    precision: u32,
    near: i32,
    /// LSE preset parameters (C.2.4.1.1): MAXVAL, T1, T2, T3, RESET; 0 = default.
    preset: [i32; 5],
    /// Offset of the entropy-coded scan data.
    scan: usize,
}

fn parse(s: &[u8]) -> Result<Header, String> {
    if !s.starts_with(&[0xFF, 0xD8]) {
        return Err("no SOI marker".into());
    }
    let u16_at = |i: usize| -> Result<usize, String> {
        s.get(i..i + 2)
            .map(|b| usize::from(u16::from_be_bytes([b[0], b[1]])))
            .ok_or_else(|| "the stream ends inside a marker segment".to_string())
    };
    let byte = |i: usize| -> Result<u8, String> {
        s.get(i)
            .copied()
            .ok_or_else(|| "the stream ends inside a marker segment".to_string())
    };
    let mut at = 2;
    let mut frame: Option<(usize, usize, u32)> = None;
    let mut preset = [0; 5];
    loop {
        if byte(at)? != 0xFF {
            return Err(format!("no marker at byte {at}"));
        }
        let marker = byte(at + 1)?;
        if marker == 0xFF {
            at += 1;
            continue;
        }
        let len = u16_at(at + 2)?;
        if len < 2 {
            return Err(format!("marker FF{marker:02X} has length {len}"));
        }
        let body = at + 4;
        match marker {
            // SOF55 (C.2.2): P, Y, X, Nf.
            0xF7 => {
                let p = u32::from(byte(body)?);
                let (y, x, nf) = (u16_at(body + 1)?, u16_at(body + 3)?, byte(body + 5)?);
                if nf != 1 {
                    return Err(format!("{nf} components (one is read)"));
                }
                if !(2..=16).contains(&p) || x == 0 || y == 0 {
                    return Err(format!("frame header P {p}, X {x}, Y {y}"));
                }
                frame = Some((x, y, p));
            }
            // LSE (C.2.4.1): preset coding parameters only.
            0xF8 => {
                let id = byte(body)?;
                if id != 1 {
                    return Err(format!(
                        "LSE marker segment ID {id} (mapping tables are not read)"
                    ));
                }
                for (k, v) in preset.iter_mut().enumerate() {
                    *v = u16_at(body + 1 + 2 * k)? as i32;
                }
            }
            // SOS (C.2.3): Ns, (Cs, Tm), NEAR, ILV, Al.
            0xDA => {
                let (x, y, p) = frame.ok_or("a scan before the frame header (SOF55)")?;
                let ns = byte(body)?;
                if ns != 1 {
                    return Err(format!("a scan of {ns} components"));
                }
                let near = i32::from(byte(body + 3)?);
                let al = byte(body + 5)? & 0x0F;
                if al != 0 {
                    return Err(format!("point transform Al {al}"));
                }
                return Ok(Header {
                    width: x,
                    height: y,
                    precision: p,
                    near,
                    preset,
                    scan: at + 2 + len,
                });
            }
            0xC0..=0xCF if marker != 0xC4 && marker != 0xC8 && marker != 0xCC => {
                return Err(format!("a JPEG (not JPEG-LS) frame header FF{marker:02X}"));
            }
            0xD9 => return Err("no scan before EOI".into()),
            _ => {}
        }
        at += 2 + len;
    }
}

/// Bit reader over entropy-coded data (A.1): after a 0xFF byte, the next
/// byte carries 7 bits (its high bit is a stuffed 0); 0xFF followed by a
/// byte with its high bit set is a marker, the end of the data.
struct Bits<'a> {
    data: &'a [u8],
    pos: usize,
    byte: u8,
    left: u32,
    after_ff: bool,
}

impl Bits<'_> {
    fn bit(&mut self) -> Result<u32, String> {
        if self.left == 0 {
            let b = *self.data.get(self.pos).ok_or("the scan data ends early")?;
            // 0xFF then a byte with its high bit set starts a marker.
            let next = self.data.get(self.pos + 1);
            if b == 0xFF && next.is_none_or(|&n| n & 0x80 != 0) {
                return Err("the scan data ends early (a marker)".into());
            }
            if self.after_ff {
                if b & 0x80 != 0 {
                    return Err("the scan data ends early (a marker)".into());
                }
                self.left = 7;
            } else {
                self.left = 8;
            }
            self.after_ff = b == 0xFF;
            self.byte = b;
            self.pos += 1;
        }
        self.left -= 1;
        Ok(u32::from(self.byte >> self.left) & 1)
    }

    fn bits(&mut self, n: u32) -> Result<i32, String> {
        let mut v = 0i32;
        for _ in 0..n {
            v = (v << 1) | self.bit()? as i32;
        }
        Ok(v)
    }

    /// The number of 0 bits before the next 1, at most `max`.
    fn zeros(&mut self, max: i32) -> Result<i32, String> {
        let mut q = 0;
        while self.bit()? == 0 {
            q += 1;
            if q > max {
                return Err("a Golomb code longer than LIMIT".into());
            }
        }
        Ok(q)
    }
}

/// The run-length order table J (A.7.1.2).
const J: [u32; 32] = [
    0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 5, 5, 6, 6, 7, 7, 8, 9, 10, 11, 12, 13,
    14, 15,
];

struct Decoder<'a> {
    bits: Bits<'a>,
    width: usize,
    height: usize,
    near: i32,
    maxval: i32,
    range: i32,
    qbpp: u32,
    limit: i32,
    reset: i32,
    t: [i32; 3],
    // Regular contexts (A.2.1): 365 of them. A and Ra sum error
    // magnitudes over up to RESET samples (65535 in an LSE segment), so
    // they are wider than the rest.
    a: Vec<i64>,
    b: Vec<i32>,
    c: Vec<i32>,
    n: Vec<i32>,
    // Run interruption contexts 365 (RItype 0) and 366 (RItype 1).
    ra: [i64; 2],
    rn: [i32; 2],
    rnn: [i32; 2],
    run_index: usize,
}

fn ceil_log2(v: i32) -> u32 {
    let mut k = 0;
    while (1i64 << k) < i64::from(v) {
        k += 1;
    }
    k
}

/// The default thresholds' basis (C.2.4.1.1.1).
const BASIC_T: [i32; 3] = [3, 7, 21];

impl<'a> Decoder<'a> {
    // The thresholds are written as C.2.4.1.1.1 states them (BASIC_T1 - 2 is 1).
    #[allow(clippy::identity_op)]
    fn new(h: &Header, data: &'a [u8]) -> Result<Self, String> {
        let maxval = if h.preset[0] > 0 {
            h.preset[0]
        } else {
            (1 << h.precision) - 1
        };
        let near = h.near;
        if near > (maxval / 2).min(255) {
            return Err(format!("NEAR {near} for MAXVAL {maxval}"));
        }
        // A.2.1 and C.2.4.1.1.
        let range = (maxval + 2 * near) / (2 * near + 1) + 1;
        let qbpp = ceil_log2(range);
        let bpp = ceil_log2(maxval + 1).max(2) as i32;
        let limit = 2 * (bpp + bpp.max(8));
        let clamp = |i: i32, j: i32| if i > maxval || i < j { j } else { i };
        let (t1, t2, t3) = if maxval >= 128 {
            let factor = (maxval.min(4095) + 128) / 256;
            let t1 = clamp(factor * (BASIC_T[0] - 2) + 2 + 3 * near, near + 1);
            let t2 = clamp(factor * (BASIC_T[1] - 3) + 3 + 5 * near, t1);
            (t1, t2, clamp(factor * (BASIC_T[2] - 4) + 4 + 7 * near, t2))
        } else {
            let factor = 256 / (maxval + 1);
            let t1 = clamp((BASIC_T[0] / factor).max(2) + 3 * near, near + 1);
            let t2 = clamp((BASIC_T[1] / factor).max(3) + 5 * near, t1);
            (t1, t2, clamp((BASIC_T[2] / factor).max(4) + 7 * near, t2))
        };
        let pick = |preset: i32, default: i32| if preset > 0 { preset } else { default };
        let t = [
            pick(h.preset[1], t1),
            pick(h.preset[2], t2),
            pick(h.preset[3], t3),
        ];
        let reset = pick(h.preset[4], 64);
        let a0 = ((range + 32) / 64).max(2);
        Ok(Decoder {
            bits: Bits {
                data,
                pos: 0,
                byte: 0,
                left: 0,
                after_ff: false,
            },
            width: h.width,
            height: h.height,
            near,
            maxval,
            range,
            qbpp,
            limit,
            reset,
            t,
            a: vec![i64::from(a0); 365],
            b: vec![0; 365],
            c: vec![0; 365],
            n: vec![1; 365],
            ra: [i64::from(a0); 2],
            rn: [1; 2],
            rnn: [0; 2],
            run_index: 0,
        })
    }

    /// Gradient quantisation (A.3.3).
    fn quantize(&self, d: i32) -> i32 {
        let [t1, t2, t3] = self.t;
        if d <= -t3 {
            -4
        } else if d <= -t2 {
            -3
        } else if d <= -t1 {
            -2
        } else if d < -self.near {
            -1
        } else if d <= self.near {
            0
        } else if d < t1 {
            1
        } else if d < t2 {
            2
        } else if d < t3 {
            3
        } else {
            4
        }
    }

    fn clamp(&self, v: i32) -> i32 {
        v.clamp(0, self.maxval)
    }

    /// Rx from a prediction and a de-quantised error, modulo the range
    /// (A.4.5, A.5.2 inverted).
    fn reconstruct(&self, px: i32, errval: i32) -> i32 {
        let step = 2 * self.near + 1;
        let mut v = px + errval * step;
        if v < -self.near {
            v += self.range * step;
        } else if v > self.maxval + self.near {
            v -= self.range * step;
        }
        self.clamp(v)
    }

    /// A limited-length Golomb code (A.5.3). The value is below 2^22
    /// (LIMIT is at most 64, k at most 16), so errors times 2·NEAR + 1
    /// stay well inside `i32`.
    fn golomb(&mut self, k: u32, limit: i32) -> Result<i32, String> {
        let escape = limit - self.qbpp as i32 - 1;
        let q = self.bits.zeros(escape)?;
        if q == escape {
            return Ok(self.bits.bits(self.qbpp)? + 1);
        }
        if k > 16 {
            return Err("a Golomb parameter over 16".into());
        }
        Ok((q << k) + self.bits.bits(k)?)
    }

    fn run(&mut self) -> Result<Vec<u16>, String> {
        let w = self.width;
        let mut out = Vec::with_capacity(w * self.height);
        // Lines with a border sample on each side (index 0 and w + 1).
        let mut prev = vec![0i32; w + 2];
        let mut cur = vec![0i32; w + 2];
        for _ in 0..self.height {
            prev[w + 1] = prev[w];
            cur[0] = prev[1];
            let mut x = 1;
            while x <= w {
                let (ra, rb, rc, rd) = (cur[x - 1], prev[x], prev[x - 1], prev[x + 1]);
                let q = (self.quantize(rd - rb) * 9 + self.quantize(rb - rc)) * 9
                    + self.quantize(rc - ra);
                if q != 0 {
                    cur[x] = self.regular(q, ra, rb, rc)?;
                    x += 1;
                } else {
                    x += self.run_mode(x, &mut cur, &prev)?;
                }
            }
            out.extend(cur[1..=w].iter().map(|&v| v as u16));
            std::mem::swap(&mut prev, &mut cur);
        }
        Ok(out)
    }

    /// One sample in regular mode (A.4 to A.6).
    fn regular(&mut self, q: i32, ra: i32, rb: i32, rc: i32) -> Result<i32, String> {
        let sign = if q < 0 { -1 } else { 1 };
        let ctx = (q * sign) as usize;
        // Median edge detector (A.4.1), then the context's bias correction.
        let px = if rc >= ra.max(rb) {
            ra.min(rb)
        } else if rc <= ra.min(rb) {
            ra.max(rb)
        } else {
            ra + rb - rc
        };
        let px = self.clamp(px + sign * self.c[ctx]);
        let mut k = 0;
        while (i64::from(self.n[ctx]) << k) < self.a[ctx] {
            k += 1;
            if k > 24 {
                return Err("a context out of range".into());
            }
        }
        let merr = self.golomb(k, self.limit)?;
        // Inverse error mapping (A.5.2), with the k = 0 special case.
        let mut err = if merr & 1 == 1 {
            -((merr + 1) >> 1)
        } else {
            merr >> 1
        };
        if k == 0 && self.near == 0 && 2 * self.b[ctx] + self.n[ctx] - 1 < 0 {
            err = -err - 1;
        }
        // Context update (A.6.1, A.6.2).
        let (a, b, c, n) = (
            &mut self.a[ctx],
            &mut self.b[ctx],
            &mut self.c[ctx],
            &mut self.n[ctx],
        );
        *a += i64::from(err.abs());
        *b += err * (2 * self.near + 1);
        if *n == self.reset {
            *a >>= 1;
            *b >>= 1;
            *n >>= 1;
        }
        *n += 1;
        if *b + *n <= 0 {
            *b += *n;
            if *b <= -*n {
                *b = -*n + 1;
            }
            if *c > -128 {
                *c -= 1;
            }
        } else if *b > 0 {
            *b -= *n;
            if *b > 0 {
                *b = 0;
            }
            if *c < 127 {
                *c += 1;
            }
        }
        Ok(self.reconstruct(px, err * sign))
    }

    /// A run from column `x` (A.7.1), and the sample that interrupts it
    /// (A.7.2) unless the run reaches the end of the line. Returns the
    /// number of samples decoded.
    fn run_mode(&mut self, x: usize, cur: &mut [i32], prev: &[i32]) -> Result<usize, String> {
        let w = self.width;
        let ra = cur[x - 1];
        let remaining = w + 1 - x;
        let mut length = 0;
        while self.bits.bit()? == 1 {
            let count = (1usize << J[self.run_index]).min(remaining - length);
            length += count;
            if count == 1 << J[self.run_index] {
                self.run_index = (self.run_index + 1).min(31);
            }
            if length == remaining {
                break;
            }
        }
        if length != remaining && J[self.run_index] > 0 {
            length += self.bits.bits(J[self.run_index])? as usize;
        }
        if length > remaining {
            return Err("a run past the end of the line".into());
        }
        cur[x..x + length].fill(ra);
        let end = x + length;
        if length == remaining {
            return Ok(length);
        }
        // Run interruption sample.
        let rb = prev[end];
        let ri = usize::from((ra - rb).abs() <= self.near);
        let temp = self.ra[ri] + i64::from(self.rn[ri] >> 1) * ri as i64;
        let mut k = 0;
        while (i64::from(self.rn[ri]) << k) < temp {
            k += 1;
            if k > 24 {
                return Err("a context out of range".into());
            }
        }
        let limit = self.limit - J[self.run_index] as i32 - 1;
        let em = self.golomb(k, limit)?;
        let t = em + ri as i32;
        let map = t & 1 == 1;
        let abs = (t + i32::from(map)) / 2;
        let err = if (k != 0 || 2 * self.rnn[ri] >= self.rn[ri]) == map {
            -abs
        } else {
            abs
        };
        if err < 0 {
            self.rnn[ri] += 1;
        }
        self.ra[ri] += i64::from((em + 1 - ri as i32) >> 1);
        if self.rn[ri] == self.reset {
            self.ra[ri] >>= 1;
            self.rn[ri] >>= 1;
            self.rnn[ri] >>= 1;
        }
        self.rn[ri] += 1;
        cur[end] = if ri == 1 {
            self.reconstruct(ra, err)
        } else {
            self.reconstruct(rb, err * if rb - ra < 0 { -1 } else { 1 })
        };
        self.run_index = self.run_index.saturating_sub(1);
        Ok(length + 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SOI, SOF55 (P 8, 2 x 3, `nf` components), an optional extra
    /// segment, SOS (1 component, NEAR 0, ILV 0, Al `al`), then `data`.
    fn stream(nf: u8, extra: &[u8], al: u8, data: &[u8]) -> Vec<u8> {
        let mut s = vec![0xFF, 0xD8, 0xFF, 0xF7, 0, 11, 8, 0, 2, 0, 3, nf, 1, 0x11, 0];
        s.extend(extra);
        s.extend([0xFF, 0xDA, 0, 8, 1, 1, 0, 0, 0, al]);
        s.extend(data);
        s.extend([0xFF, 0xD9]);
        s
    }

    #[test]
    fn unsupported_and_cut_streams_are_errors() {
        let err = |s: &[u8]| decode(s, 100).unwrap_err();
        assert_eq!(
            err(&stream(3, &[], 0, &[0; 4])),
            "3 components (one is read)"
        );
        let mapping = [0xFF, 0xF8, 0, 5, 2, 0, 0];
        assert!(err(&stream(1, &mapping, 0, &[0; 4])).contains("LSE marker segment ID 2"));
        assert_eq!(err(&stream(1, &[], 1, &[0; 4])), "point transform Al 1");
        assert!(err(&[0xFF, 0xD8, 0xFF, 0xDA, 0, 8]).contains("before the frame header"));
        // Scan data that ends before six samples are decoded.
        assert!(err(&stream(1, &[], 0, &[])).contains("ends early"));
        assert!(
            decode(&stream(1, &[], 0, &[0; 4]), 5)
                .unwrap_err()
                .contains("larger than the image")
        );
    }

    #[test]
    fn a_scan_header_length_past_the_stream_is_an_error() {
        // SOS's length 0xFF00 puts the scan data far past the stream's end
        // (issue 41: this sliced out of bounds, a panic).
        let mut s = stream(1, &[], 0, &[0xFC]);
        let sos = s.windows(2).position(|w| w == [0xFF, 0xDA]).unwrap();
        s[sos + 2] = 0xFF;
        let err = decode(&s, 6).unwrap_err();
        assert!(err.contains("past the stream's end"), "{err}");
    }

    #[test]
    fn a_flat_image_is_one_run_per_line() {
        // Every sample 0: each line of 3 is one run. RUNindex 0 codes a
        // run of 1 per 1 bit (J = 0), so "111" per line: 6 one bits, then
        // padding. The data bits 1111 1100 decode to six zeros.
        let got = decode(&stream(1, &[], 0, &[0xFC]), 6).unwrap();
        assert_eq!(got, [0; 6]);
    }
}
