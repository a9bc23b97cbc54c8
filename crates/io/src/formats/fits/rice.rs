//! Rice decoding of a compressed FITS tile (FITS Standard 4.0 §10.4.1:
//! the adaptive Rice code of Rice, Yeh & Miller as `fpack` and cfitsio write
//! it), for `tiled.rs`.

/// Rice decoding (§10.4.1, as `fpack` writes it): the first value in
/// `bytepix` bytes, then blocks of `block` differences, each block led by
/// its split `fs + 1` in 3, 4 or 5 bits (1, 2, 4 bytes a value): 0 for a
/// block of zero differences, the largest for differences stored whole,
/// else each difference as a unary high part and `fs` low bits, folded to
/// unsigned (even ≥ 0, odd < 0). Arithmetic wraps at the value's width.
pub(super) fn rice(
    data: &[u8],
    n: usize,
    block: usize,
    bytepix: usize,
) -> Result<Vec<i64>, String> {
    let (fsbits, fsmax, bbits) = match bytepix {
        1 => (3, 6, 8),
        2 => (4, 14, 16),
        4 => (5, 25, 32),
        _ => return Err(format!("Rice with {bytepix} bytes a value is not read")),
    };
    let mask: u64 = (1u64 << bbits) - 1;
    let first = data
        .get(..bytepix)
        .ok_or("the Rice stream is shorter than its first value")?;
    let mut last = first.iter().fold(0u64, |v, &b| (v << 8) | u64::from(b));
    let mut bits = RiceBits {
        data,
        at: bytepix * 8,
    };
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let end = (out.len() + block).min(n);
        let fs = bits.take(fsbits)? as i64 - 1;
        if fs < 0 {
            while out.len() < end {
                out.push(last);
            }
            continue;
        }
        while out.len() < end {
            let folded = if fs == fsmax {
                bits.take(bbits)?
            } else {
                let high = bits.zeros()?;
                (high << fs) | bits.take(fs as u32)?
            };
            let diff = if folded & 1 == 0 {
                folded >> 1
            } else {
                !(folded >> 1)
            };
            last = last.wrapping_add(diff) & mask;
            out.push(last);
        }
    }
    Ok(out
        .into_iter()
        .map(|v| match bytepix {
            1 => v as i64,
            2 => i64::from(v as u16 as i16),
            _ => i64::from(v as u32 as i32),
        })
        .collect())
}

/// Bits of a Rice stream, most significant first.
struct RiceBits<'a> {
    data: &'a [u8],
    /// The next bit's position.
    at: usize,
}

impl RiceBits<'_> {
    fn bit(&mut self) -> Result<u64, String> {
        let byte = self
            .data
            .get(self.at / 8)
            .ok_or("the Rice stream ends early")?;
        let b = (byte >> (7 - self.at % 8)) & 1;
        self.at += 1;
        Ok(u64::from(b))
    }

    fn take(&mut self, n: u32) -> Result<u64, String> {
        (0..n).try_fold(0, |v, _| Ok((v << 1) | self.bit()?))
    }

    /// The zeros before the next one (which is consumed).
    fn zeros(&mut self) -> Result<u64, String> {
        let mut n = 0;
        while self.bit()? == 0 {
            n += 1;
            if n > 64 {
                return Err("a Rice code of more than 64 zeros".into());
            }
        }
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rice-encodes `values` as §10.4.1 says (the encoder `fpack` runs),
    /// for the decoder's round trip.
    fn rice_encode(values: &[i64], block: usize, bytepix: usize) -> Vec<u8> {
        let (fsbits, fsmax, bbits) = match bytepix {
            1 => (3u32, 6u64, 8u32),
            2 => (4, 14, 16),
            _ => (5, 25, 32),
        };
        let mask = (1u64 << bbits) - 1;
        let mut bits: Vec<u8> = Vec::new();
        let put = |bits: &mut Vec<u8>, v: u64, n: u32| {
            bits.extend((0..n).rev().map(|i| ((v >> i) & 1) as u8));
        };
        let first = values[0] as u64 & mask;
        put(&mut bits, first, 8 * bytepix as u32);
        let mut last = first;
        for chunk in values.chunks(block) {
            let folded: Vec<u64> = (chunk.iter())
                .map(|&v| {
                    let v = v as u64 & mask;
                    let d = v.wrapping_sub(last) & mask;
                    last = v;
                    // Signed difference at the value's width, folded.
                    let s = ((d << (64 - bbits)) as i64) >> (64 - bbits);
                    if s >= 0 {
                        (s as u64) << 1
                    } else {
                        ((!s as u64) << 1) | 1
                    }
                })
                .collect();
            if folded.iter().all(|&f| f == 0) {
                put(&mut bits, 0, fsbits);
                continue;
            }
            // The split that codes the block shortest, or whole values.
            let cost = |fs: u64| -> u64 { folded.iter().map(|&f| (f >> fs) + 1 + fs).sum() };
            let fs = (0..fsmax).min_by_key(|&fs| cost(fs)).unwrap();
            if cost(fs) >= u64::from(bbits) * folded.len() as u64 {
                put(&mut bits, fsmax + 1, fsbits);
                for &f in &folded {
                    put(&mut bits, f, bbits);
                }
                continue;
            }
            put(&mut bits, fs + 1, fsbits);
            for &f in &folded {
                bits.extend(std::iter::repeat_n(0, (f >> fs) as usize));
                bits.push(1);
                put(&mut bits, f & ((1 << fs) - 1), fs as u32);
            }
        }
        while !bits.len().is_multiple_of(8) {
            bits.push(0);
        }
        bits.chunks(8)
            .map(|b| b.iter().fold(0, |a, &x| (a << 1) | x))
            .collect()
    }

    #[test]
    fn rice_round_trips_at_every_width() {
        for bytepix in [1usize, 2, 4] {
            let lo = match bytepix {
                1 => 0i64,
                2 => i64::from(i16::MIN),
                _ => i64::from(i32::MIN),
            };
            let hi = match bytepix {
                1 => 255i64,
                2 => i64::from(i16::MAX),
                _ => i64::from(i32::MAX),
            };
            // Flat runs (zero blocks), small steps, and jumps across the
            // whole range (whole values).
            let mut values = vec![7i64; 40];
            values.extend((0..50).map(|i| 7 + i % 5));
            values.extend([lo, hi, lo, 0, hi, 1]);
            values.extend((0..33).map(|i| (i * 97) % 200));
            let stream = rice_encode(&values, 32, bytepix);
            assert_eq!(rice(&stream, values.len(), 32, bytepix).unwrap(), values);
            // Cut short: an error, not a panic.
            assert!(rice(&stream[..stream.len() / 2], values.len(), 32, bytepix).is_err());
        }
    }
}
