//! volray's own decoder of 12-bit DCT JPEG: ISO 10918-1's extended
//! sequential process with Huffman coding (process 4, SOF1 at P = 12),
//! one component: the JPEG Extended transfer syntax
//! (1.2.840.10008.1.2.4.51) that CT and MR archives of the 1990s and 2000s
//! hold, which `jpeg-decoder` (8-bit DCT only) does not read.
//!
//! The stream is read in the order T.81 lays it out (Annex B): tables
//! (DQT, 8- or 16-bit entries; DHT, up to four DC and four AC tables),
//! the frame header, the restart interval, one scan; then each 8×8 block
//! is Huffman-decoded (F.2.2: the DC difference, then run/size pairs to
//! the end of block), dequantised, inverse-transformed (A.3.3, the
//! separable IDCT in `f64`) and level-shifted by 2^(P−1) = 2048 into
//! 0..=4095. A single-component scan is not interleaved: its blocks run
//! in raster order over ⌈X/8⌉ × ⌈Y/8⌉ whatever the sampling factors
//! (A.2.2), cropped to X × Y.
//!
//! Lossy: decoders differ by rounding. This one computes the IDCT in
//! double precision and rounds once, which T.81's accuracy test (A.3.3's
//! reference IDCT) is; libjpeg's integer `islow` IDCT, which pydicom's
//! decoders use, lies within 1 of it on the fixtures.
//!
//! Every length and index is checked: a corrupt stream is an error
//! naming what is wrong, never a panic, and the output is sized from the
//! frame header, which the caller has checked against the DICOM header.

/// Zig-zag position `k` → natural (row-major) index in the 8×8 block
/// (T.81 Figure A.6).
const ZIGZAG: [usize; 64] = [
    0, 1, 8, 16, 9, 2, 3, 10, 17, 24, 32, 25, 18, 11, 4, 5, 12, 19, 26, 33, 40, 48, 41, 34, 27, 20,
    13, 6, 7, 14, 21, 28, 35, 42, 49, 56, 57, 50, 43, 36, 29, 22, 15, 23, 30, 37, 44, 51, 58, 59,
    52, 45, 38, 31, 39, 46, 53, 60, 61, 54, 47, 55, 62, 63,
];

/// The precision this decoder reads.
const PRECISION: u8 = 12;

/// A Huffman table as F.2.2.3 decodes with it: per code length `l`
/// (1..=16), the largest code of that length (`max_code`, −1 if none),
/// the index into `values` of its first code (`val_ptr`) and that code
/// (`min_code`).
#[derive(Clone)]
struct Huffman {
    min_code: [i32; 17],
    max_code: [i32; 17],
    val_ptr: [usize; 17],
    values: Vec<u8>,
}

impl Huffman {
    /// The table of `counts` codes of each length 1..=16 and their
    /// `values` (B.2.4.2), its codes generated as C.2 says.
    fn new(counts: &[u8; 16], values: Vec<u8>) -> Result<Huffman, String> {
        let total: usize = counts.iter().map(|&c| usize::from(c)).sum();
        if total != values.len() || total > 256 {
            return Err(format!(
                "a Huffman table declares {total} codes for {} values",
                values.len()
            ));
        }
        let mut h = Huffman {
            min_code: [0; 17],
            max_code: [-1; 17],
            val_ptr: [0; 17],
            values,
        };
        let (mut code, mut k) = (0i32, 0usize);
        for l in 1..=16 {
            let n = usize::from(counts[l - 1]);
            if n > 0 {
                h.val_ptr[l] = k;
                h.min_code[l] = code;
                code += n as i32;
                k += n;
                h.max_code[l] = code - 1;
                // Codes of one length must fit in it (C.2).
                if code > (1 << l) {
                    return Err("a Huffman table has more codes than its lengths hold".into());
                }
            }
            code <<= 1;
        }
        Ok(h)
    }
}

/// The entropy-coded bits of a scan, its stuffed zero bytes removed
/// (F.1.2.3); a marker ends the bits (reading on gives zeros, which a
/// restart or the end of the scan then checks).
struct Bits<'a> {
    data: &'a [u8],
    at: usize,
    buffer: u32,
    count: u32,
    /// A marker (other than a stuffed 0xFF00) was met at `at`.
    marker: bool,
}

impl<'a> Bits<'a> {
    fn new(data: &'a [u8], at: usize) -> Self {
        Bits {
            data,
            at,
            buffer: 0,
            count: 0,
            marker: false,
        }
    }

    fn bit(&mut self) -> u32 {
        if self.count == 0 {
            let byte = match (self.marker, self.data.get(self.at)) {
                (false, Some(&0xFF)) => match self.data.get(self.at + 1) {
                    Some(0x00) => {
                        self.at += 2;
                        0xFF
                    }
                    _ => {
                        self.marker = true;
                        0
                    }
                },
                (false, Some(&b)) => {
                    self.at += 1;
                    b
                }
                _ => 0,
            };
            self.buffer = u32::from(byte);
            self.count = 8;
        }
        self.count -= 1;
        (self.buffer >> self.count) & 1
    }

    /// `n` bits (n ≤ 16), first bit highest.
    fn bits(&mut self, n: u32) -> u32 {
        (0..n).fold(0, |v, _| (v << 1) | self.bit())
    }

    /// The value of the next Huffman code of `table` (F.2.2.3, DECODE).
    fn decode(&mut self, table: &Huffman) -> Result<u8, String> {
        let mut code = self.bit() as i32;
        for l in 1..=16 {
            if table.max_code[l] >= code && table.max_code[l] >= 0 {
                let i = table.val_ptr[l] + (code - table.min_code[l]) as usize;
                return table
                    .values
                    .get(i)
                    .copied()
                    .ok_or_else(|| "a Huffman code points past its table".into());
            }
            code = (code << 1) | self.bit() as i32;
        }
        Err(format!(
            "no Huffman code matches the bits before byte {}",
            self.at
        ))
    }

    /// RECEIVE(s) then EXTEND (F.2.2.1): the signed value of `s` bits.
    fn receive_extend(&mut self, s: u8) -> i32 {
        if s == 0 {
            return 0;
        }
        let v = self.bits(u32::from(s)) as i32;
        if v < 1 << (s - 1) {
            v - (1 << s) + 1
        } else {
            v
        }
    }

    /// After a restart interval: the RSTm marker expected next (E.1.4),
    /// the bits and the DC prediction start again.
    fn restart(&mut self, m: u8) -> Result<(), String> {
        self.count = 0;
        self.marker = false;
        let want = 0xD0 + (m & 7);
        match self.data.get(self.at..self.at + 2) {
            Some([0xFF, got]) if *got == want => {
                self.at += 2;
                Ok(())
            }
            _ => Err(format!(
                "restart marker FF{want:02X} expected at byte {}",
                self.at
            )),
        }
    }
}

/// Decodes the 12-bit sequential DCT JPEG `stream` (one component) of
/// `pixels` samples into its samples, row by row.
pub(super) fn decode(stream: &[u8], pixels: usize) -> Result<Vec<u16>, String> {
    let mut quant: [Option<[u16; 64]>; 4] = [None; 4];
    let mut dc: [Option<Huffman>; 4] = [None, None, None, None];
    let mut ac: [Option<Huffman>; 4] = [None, None, None, None];
    let mut frame: Option<(usize, usize, usize)> = None; // width, height, Tq
    let mut restart = 0usize;
    let mut at = 2; // after SOI, which the header check saw
    loop {
        while stream.get(at) == Some(&0xFF) && stream.get(at + 1) == Some(&0xFF) {
            at += 1;
        }
        let (Some(&0xFF), Some(&marker)) = (stream.get(at), stream.get(at + 1)) else {
            return Err(format!("a marker expected at byte {at}"));
        };
        let Some(len) = stream.get(at + 2..at + 4) else {
            return Err("the stream ends inside a marker segment".into());
        };
        let len = usize::from(u16::from_be_bytes([len[0], len[1]]));
        let Some(body) = stream.get(at + 4..(at + 2 + len).max(at + 4)) else {
            return Err(format!(
                "marker FF{marker:02X} at byte {at} runs past the stream"
            ));
        };
        if len < 2 {
            return Err(format!(
                "marker FF{marker:02X} at byte {at} has length {len}"
            ));
        }
        match marker {
            0xDB => read_quant(body, &mut quant)?,
            0xC4 => read_huffman(body, &mut dc, &mut ac)?,
            0xDD => {
                let r = body.get(..2).ok_or("a DRI segment too short")?;
                restart = usize::from(u16::from_be_bytes([r[0], r[1]]));
            }
            0xC1 => frame = Some(read_frame(body)?),
            0xDA => {
                let (width, height, tq) = frame.ok_or("the scan comes before the frame header")?;
                let q = quant[tq].ok_or(format!("quantisation table {tq} is not defined"))?;
                let (td, ta) = read_scan(body)?;
                let dc = dc[td]
                    .as_ref()
                    .ok_or(format!("DC table {td} is not defined"))?;
                let ac = ac[ta]
                    .as_ref()
                    .ok_or(format!("AC table {ta} is not defined"))?;
                if width * height != pixels {
                    return Err(format!("{width}x{height} samples, not {pixels}"));
                }
                let mut bits = Bits::new(stream, at + 2 + len);
                return scan(&mut bits, (width, height), &q, (dc, ac), restart);
            }
            0xC0 | 0xC2 | 0xC3 | 0xC5..=0xC7 | 0xC9..=0xCB | 0xCD..=0xCF => {
                return Err(format!(
                    "SOF marker FF{marker:02X}: only the extended sequential process (SOF1) is read at 12 bits"
                ));
            }
            0xD9 => return Err("the stream ends (EOI) before its scan".into()),
            _ => {} // APPn, COM, DNL...: skipped by their lengths
        }
        at += 2 + len;
    }
}

/// DQT (B.2.4.1): tables of 64 entries, 8-bit (Pq = 0) or 16-bit (Pq = 1),
/// in zig-zag order, kept in natural order.
fn read_quant(mut body: &[u8], quant: &mut [Option<[u16; 64]>; 4]) -> Result<(), String> {
    while let Some((&pq_tq, rest)) = body.split_first() {
        let (wide, tq) = (pq_tq >> 4, usize::from(pq_tq & 15));
        let size = if wide == 1 { 128 } else { 64 };
        let (Some(values), true) = (rest.get(..size), tq < 4 && wide <= 1) else {
            return Err(format!("a DQT table (Pq {wide}, Tq {tq}) is malformed"));
        };
        let mut table = [0u16; 64];
        for (k, &natural) in ZIGZAG.iter().enumerate() {
            table[natural] = match wide {
                1 => u16::from_be_bytes([values[2 * k], values[2 * k + 1]]),
                _ => u16::from(values[k]),
            };
        }
        quant[tq] = Some(table);
        body = &rest[size..];
    }
    Ok(())
}

/// DHT (B.2.4.2): class (0 DC, 1 AC), destination 0..=3, 16 counts and
/// the values.
fn read_huffman(
    mut body: &[u8],
    dc: &mut [Option<Huffman>; 4],
    ac: &mut [Option<Huffman>; 4],
) -> Result<(), String> {
    while let Some((&tc_th, rest)) = body.split_first() {
        let (class, th) = (tc_th >> 4, usize::from(tc_th & 15));
        let Some(counts) = rest.get(..16) else {
            return Err("a DHT segment ends inside its counts".into());
        };
        let counts: [u8; 16] = counts.try_into().expect("16 bytes");
        let n: usize = counts.iter().map(|&c| usize::from(c)).sum();
        let (Some(values), true) = (rest.get(16..16 + n), th < 4 && class <= 1) else {
            return Err(format!("a DHT table (Tc {class}, Th {th}) is malformed"));
        };
        let table = Huffman::new(&counts, values.to_vec())?;
        match class {
            0 => dc[th] = Some(table),
            _ => ac[th] = Some(table),
        }
        body = &rest[16 + n..];
    }
    Ok(())
}

/// SOF1 (B.2.2): P = 12, Y, X, one component; its width, height and
/// quantisation table.
fn read_frame(body: &[u8]) -> Result<(usize, usize, usize), String> {
    let b = body.get(..6).ok_or("the frame header is too short")?;
    let (p, y0, y1, x0, x1, nf) = (b[0], b[1], b[2], b[3], b[4], b[5]);
    if p != PRECISION {
        return Err(format!("precision {p}, not {PRECISION}"));
    }
    if nf != 1 {
        return Err(format!("{nf} components: a greyscale image has one"));
    }
    let tq = usize::from(*body.get(8).ok_or("the frame header is too short")?);
    let (height, width) = (
        usize::from(u16::from_be_bytes([y0, y1])),
        usize::from(u16::from_be_bytes([x0, x1])),
    );
    if height == 0 || width == 0 || tq > 3 {
        return Err(format!("a {width}x{height} frame with table {tq}"));
    }
    Ok((width, height, tq))
}

/// SOS (B.2.3): one component, the whole spectrum (Ss 0, Se 63, no
/// successive approximation); its DC and AC tables.
fn read_scan(body: &[u8]) -> Result<(usize, usize), String> {
    let b = body.get(..6).ok_or("the scan header is too short")?;
    let (ns, td_ta, ss, se, ah_al) = (b[0], b[2], b[3], b[4], b[5]);
    if ns != 1 || ss != 0 || se != 63 || ah_al != 0 {
        return Err(format!(
            "a scan of {ns} component(s), spectrum {ss}..{se}, approximation {ah_al:02X}: not sequential"
        ));
    }
    let (td, ta) = (usize::from(td_ta >> 4), usize::from(td_ta & 15));
    if td > 3 || ta > 3 {
        return Err(format!("scan tables {td} and {ta}"));
    }
    Ok((td, ta))
}

/// The scan's blocks decoded into the image (see the module doc).
fn scan(
    bits: &mut Bits,
    (width, height): (usize, usize),
    quant: &[u16; 64],
    (dc, ac): (&Huffman, &Huffman),
    restart: usize,
) -> Result<Vec<u16>, String> {
    let (across, down) = (width.div_ceil(8), height.div_ceil(8));
    let mut image = vec![0u16; width * height];
    let mut prediction = 0i32;
    let mut coefficients = [0i32; 64];
    let mut samples = [0f64; 64];
    let cosines = cosines();
    for block in 0..across * down {
        if restart > 0 && block > 0 && block.is_multiple_of(restart) {
            bits.restart(((block / restart - 1) % 8) as u8)?;
            prediction = 0;
        }
        // F.2.2.1: the DC difference.
        let t = bits.decode(dc)?;
        if t > 15 {
            return Err(format!("DC magnitude category {t}"));
        }
        // Wrapping: a corrupt stream's differences may add up past i32.
        prediction = prediction.wrapping_add(bits.receive_extend(t));
        coefficients.fill(0);
        coefficients[0] = prediction;
        // F.2.2.2: run/size pairs to the end of block.
        let mut k = 1;
        while k < 64 {
            let rs = bits.decode(ac)?;
            let (run, size) = (usize::from(rs >> 4), rs & 15);
            if size == 0 {
                if run != 15 {
                    break; // EOB
                }
                k += 16;
                continue;
            }
            k += run;
            if k > 63 || size > 15 {
                return Err(format!(
                    "an AC coefficient beyond the block (k {k}, size {size})"
                ));
            }
            coefficients[ZIGZAG[k]] = bits.receive_extend(size);
            k += 1;
        }
        idct(&coefficients, quant, &cosines, &mut samples);
        let (bx, by) = (block % across * 8, block / across * 8);
        for y in 0..8.min(height - by) {
            for x in 0..8.min(width - bx) {
                let v = (samples[y * 8 + x] + 2048.0).round().clamp(0.0, 4095.0);
                image[(by + y) * width + bx + x] = v as u16;
            }
        }
    }
    Ok(image)
}

/// `C(u)/2 · cos((2x + 1)uπ/16)` at `[u][x]` (A.3.3).
fn cosines() -> [[f64; 8]; 8] {
    let mut c = [[0.0; 8]; 8];
    for (u, row) in c.iter_mut().enumerate() {
        let cu = if u == 0 {
            std::f64::consts::FRAC_1_SQRT_2
        } else {
            1.0
        };
        for (x, v) in row.iter_mut().enumerate() {
            *v = cu / 2.0 * ((2 * x + 1) as f64 * u as f64 * std::f64::consts::PI / 16.0).cos();
        }
    }
    c
}

/// The inverse DCT of the dequantised `coefficients` (A.3.3:
/// `s(y, x) = Σ_v Σ_u C(u)C(v)/4 · S(v, u) cos(..x..u) cos(..y..v)`),
/// rows then columns.
fn idct(coefficients: &[i32; 64], quant: &[u16; 64], c: &[[f64; 8]; 8], out: &mut [f64; 64]) {
    let mut rows = [0f64; 64];
    for v in 0..8 {
        for x in 0..8 {
            rows[v * 8 + x] = (0..8)
                .map(|u| f64::from(coefficients[v * 8 + u]) * f64::from(quant[v * 8 + u]) * c[u][x])
                .sum();
        }
    }
    for y in 0..8 {
        for x in 0..8 {
            out[y * 8 + x] = (0..8).map(|v| rows[v * 8 + x] * c[v][y]).sum();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dc_only_block_is_its_mean_and_an_ac_term_its_cosine() {
        let c = cosines();
        let quant = [1u16; 64];
        let mut out = [0f64; 64];
        // DC alone: S(0,0)/8 everywhere (C(0)² / 4 = 1/8).
        let mut coefficients = [0i32; 64];
        coefficients[0] = 80;
        idct(&coefficients, &quant, &c, &mut out);
        assert!(out.iter().all(|&v| (v - 10.0).abs() < 1e-9));
        // S(0,1) = 8: s(y, x) = 8 · C(0)C(1)/4 · cos((2x+1)π/16).
        coefficients[0] = 0;
        coefficients[1] = 8;
        idct(&coefficients, &quant, &c, &mut out);
        for x in 0..8 {
            let want = 8.0 * std::f64::consts::FRAC_1_SQRT_2 / 4.0
                * ((2 * x + 1) as f64 * std::f64::consts::PI / 16.0).cos();
            assert!((out[x] - want).abs() < 1e-9 && (out[56 + x] - want).abs() < 1e-9);
        }
    }

    #[test]
    fn huffman_codes_are_generated_canonically() {
        // Two codes of length 2 (00, 01), one of length 3 (100).
        let mut counts = [0u8; 16];
        counts[1] = 2;
        counts[2] = 1;
        let h = Huffman::new(&counts, vec![7, 8, 9]).unwrap();
        let stream = [0b0001_1000, 0];
        let mut bits = Bits::new(&stream, 0);
        assert_eq!(bits.decode(&h), Ok(7));
        assert_eq!(bits.decode(&h), Ok(8));
        assert_eq!(bits.decode(&h), Ok(9));
        // Too many codes for their lengths.
        let mut counts = [0u8; 16];
        counts[0] = 3;
        assert!(Huffman::new(&counts, vec![1, 2, 3]).is_err());
    }

    #[test]
    fn extend_gives_the_signed_value_of_its_bits() {
        // s = 3: 000..011 are −7..−4, 100..111 are 4..7 (Table F.1).
        let stream = [0b0001_1100, 0];
        let mut bits = Bits::new(&stream, 0);
        assert_eq!(bits.receive_extend(3), -7);
        assert_eq!(bits.receive_extend(3), 7);
        assert_eq!(bits.receive_extend(0), 0);
    }

    #[test]
    fn a_stuffed_ff_is_data_and_a_marker_ends_the_bits() {
        let stream = [0xFF, 0x00, 0xFF, 0xD9];
        let mut bits = Bits::new(&stream, 0);
        assert_eq!(bits.bits(8), 0xFF);
        assert_eq!(bits.bits(8), 0);
        assert!(bits.marker);
    }

    /// A 12-bit stream of flat 8×8 blocks `values` in a row, written as
    /// T.81 says, DC only: every quantiser 1 (8-bit DQT), a DC table of
    /// sixteen 4-bit codes (category c is code c), an AC table whose one
    /// code `0` is the end of block; with `restart` (DRI) 1, an RSTm after
    /// every block numbered from `first_rst`.
    fn flat_blocks(values: &[u16], restart: bool, first_rst: u8) -> Vec<u8> {
        let mut s = vec![0xFF, 0xD8];
        s.extend([0xFF, 0xDB, 0, 67, 0x00]);
        s.extend([1u8; 64]);
        s.extend([0xFF, 0xC4, 0, 3 + 16 + 16, 0x00]);
        s.extend([0, 0, 0, 16, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]);
        s.extend(0u8..16);
        s.extend([0xFF, 0xC4, 0, 3 + 16 + 1, 0x10, 1]);
        s.extend([0u8; 15]);
        s.push(0x00);
        if restart {
            s.extend([0xFF, 0xDD, 0, 4, 0, 1]);
        }
        let width = 8 * values.len() as u16;
        s.extend([0xFF, 0xC1, 0, 11, 12, 0, 8]);
        s.extend(width.to_be_bytes());
        s.extend([1, 1, 0x11, 0]);
        s.extend([0xFF, 0xDA, 0, 8, 1, 1, 0x00, 0, 63, 0]);
        let (mut bits, mut previous): (Vec<u8>, i32) = (Vec::new(), 0);
        let flush = |bits: &mut Vec<u8>, s: &mut Vec<u8>| {
            while !bits.len().is_multiple_of(8) {
                bits.push(1);
            }
            for byte in bits.chunks(8) {
                let byte = byte.iter().fold(0u8, |b, &bit| (b << 1) | bit);
                s.push(byte);
                if byte == 0xFF {
                    s.push(0);
                }
            }
            bits.clear();
        };
        let put = |bits: &mut Vec<u8>, value: u32, n: u32| {
            bits.extend((0..n).rev().map(|i| ((value >> i) & 1) as u8));
        };
        for (b, &v) in values.iter().enumerate() {
            let dc = 8 * (i32::from(v) - 2048);
            let diff = dc - previous;
            previous = if restart { 0 } else { dc };
            let cat = 32 - diff.unsigned_abs().leading_zeros();
            let coded = if diff >= 0 {
                diff
            } else {
                diff + (1 << cat) - 1
            };
            put(&mut bits, cat, 4);
            put(&mut bits, coded as u32, cat);
            put(&mut bits, 0, 1); // EOB
            if restart && b + 1 < values.len() {
                flush(&mut bits, &mut s);
                s.extend([0xFF, 0xD0 + (first_rst + b as u8) % 8]);
            }
        }
        flush(&mut bits, &mut s);
        s.extend([0xFF, 0xD9]);
        s
    }

    #[test]
    fn flat_blocks_decode_to_their_values_with_and_without_restarts() {
        let values = [3000, 1000, 4095, 0, 2048, 2049, 7, 9, 4000, 1];
        for restart in [false, true] {
            let stream = flat_blocks(&values, restart, 0);
            let image = decode(&stream, 64 * values.len()).unwrap();
            let width = 8 * values.len();
            for (b, &v) in values.iter().enumerate() {
                for y in 0..8 {
                    for x in 0..8 {
                        assert_eq!(image[y * width + 8 * b + x], v, "block {b}, {restart}");
                    }
                }
            }
        }
        // Restart markers out of order are named.
        let stream = flat_blocks(&values, true, 3);
        let err = decode(&stream, 64 * values.len()).unwrap_err();
        assert!(err.contains("restart marker FFD0 expected"), "{err}");
    }

    #[test]
    fn truncated_and_garbled_streams_are_errors_not_panics() {
        let soi = [0xFF, 0xD8];
        assert!(decode(&soi, 4).is_err());
        let mut cut = soi.to_vec();
        cut.extend([0xFF, 0xC1, 0x00, 0x0B, 12, 0, 2]);
        assert!(decode(&cut, 4).is_err());
        for seed in 0u32..200 {
            let mut s = seed.wrapping_mul(2_654_435_761);
            let mut stream = soi.to_vec();
            for _ in 0..64 {
                s ^= s << 13;
                s ^= s >> 17;
                s ^= s << 5;
                stream.push((s & 0xFF) as u8);
            }
            let _ = decode(&stream, 64);
        }
    }
}
