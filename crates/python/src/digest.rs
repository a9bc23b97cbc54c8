//! A 64-bit digest of a numpy array's bytes, taken before every frame so
//! that a `Renderer` over an array the caller changed in place renders
//! what the array holds now, not the value range, histogram and bricks
//! of what it held when the renderer was made.
//!
//! numpy keeps no count of writes to an array (no version number, no
//! dirty flag; a write through any view, a C extension or a memory map
//! changes the bytes and nothing else), so the only sure way to know the
//! samples are unchanged is to read them all. Reading is what costs: the
//! hash is XXH64 (Yann Collet's, the 64-bit xxHash: four independent
//! multiply-rotate lanes, about 1.5 bytes per cycle per core, faster than
//! a core streams memory) over 1 MiB chunks in parallel, the chunks'
//! digests then hashed in order. Any change of any sample changes the
//! digest except with probability about 2⁻⁶⁴.
//!
//! Measured (docs/python.md, `scripts/python_digest.py`): 256³ u16 (32 MiB)
//! and 512³ u8 (128 MiB) against their frames.

use rayon::prelude::*;

const P1: u64 = 0x9E37_79B1_85EB_CA87;
const P2: u64 = 0xC2B2_AE3D_27D4_EB4F;
const P3: u64 = 0x1656_67B1_9E37_79F9;
const P4: u64 = 0x85EB_CA77_C2B2_AE63;
const P5: u64 = 0x27D4_EB2F_1656_67C5;

/// Bytes per chunk hashed on one worker: large enough that the chunk
/// digests (8 bytes per MiB) cost nothing, small enough that a 32 MiB
/// array splits over every core.
const CHUNK: usize = 1 << 20;

/// The digest of `bytes`, hashed in parallel on the current rayon pool.
pub fn digest(bytes: &[u8]) -> u64 {
    let chunks: Vec<u8> = (bytes.par_chunks(CHUNK).enumerate())
        .map(|(i, chunk)| xxh64(chunk, i as u64).to_le_bytes())
        .collect::<Vec<_>>()
        .concat();
    xxh64(&chunks, bytes.len() as u64)
}

fn round(acc: u64, input: u64) -> u64 {
    acc.wrapping_add(input.wrapping_mul(P2))
        .rotate_left(31)
        .wrapping_mul(P1)
}

fn merge(acc: u64, lane: u64) -> u64 {
    (acc ^ round(0, lane)).wrapping_mul(P1).wrapping_add(P4)
}

fn word(bytes: &[u8]) -> u64 {
    u64::from_le_bytes(bytes[..8].try_into().expect("eight bytes"))
}

/// XXH64 of `bytes` with `seed`, as the reference implementation computes
/// it (its test vectors: "" → 0xEF46DB3751D8E999, "abc" →
/// 0x44BC2CF5AD770999, "Nobody inspects the spammish repetition" →
/// 0xFBCEA83C8A378BF1, all with seed 0; checked when this was written).
pub fn xxh64(bytes: &[u8], seed: u64) -> u64 {
    let mut stripes = bytes.chunks_exact(32);
    let mut h = if bytes.len() >= 32 {
        let mut v = [
            seed.wrapping_add(P1).wrapping_add(P2),
            seed.wrapping_add(P2),
            seed,
            seed.wrapping_sub(P1),
        ];
        for stripe in &mut stripes {
            for (lane, input) in v.iter_mut().zip(stripe.chunks_exact(8)) {
                *lane = round(*lane, word(input));
            }
        }
        let h = (v[0].rotate_left(1))
            .wrapping_add(v[1].rotate_left(7))
            .wrapping_add(v[2].rotate_left(12))
            .wrapping_add(v[3].rotate_left(18));
        v.iter().fold(h, |h, &lane| merge(h, lane))
    } else {
        seed.wrapping_add(P5)
    };
    h = h.wrapping_add(bytes.len() as u64);
    let mut rest = stripes.remainder();
    while rest.len() >= 8 {
        h = (h ^ round(0, word(rest)))
            .rotate_left(27)
            .wrapping_mul(P1)
            .wrapping_add(P4);
        rest = &rest[8..];
    }
    if rest.len() >= 4 {
        let k = u64::from(u32::from_le_bytes(
            rest[..4].try_into().expect("four bytes"),
        ));
        h = (h ^ k.wrapping_mul(P1))
            .rotate_left(23)
            .wrapping_mul(P2)
            .wrapping_add(P3);
        rest = &rest[4..];
    }
    for &b in rest {
        h = (h ^ u64::from(b).wrapping_mul(P5))
            .rotate_left(11)
            .wrapping_mul(P1);
    }
    h ^= h >> 33;
    h = h.wrapping_mul(P2);
    h ^= h >> 29;
    h = h.wrapping_mul(P3);
    h ^ (h >> 32)
}
