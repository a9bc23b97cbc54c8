"""Writes the raw target's seeds (fuzz/seeds/raw/): a 25-byte layout
(dtype byte, dims as three little-endian u32, spacing as three
little-endian f32) followed by exactly the samples it describes, for every
sample type and both byte orders, plus a few sizes. See
fuzz_targets/raw.rs for the layout."""
import struct
import pathlib

SIZES = [1, 1, 2, 2, 4, 4, 8, 8, 2, 4, 8]  # u8 i8 u16 i16 u32 i32 u64 i64 f16 f32 f64
out = pathlib.Path(__file__).parent / "seeds" / "raw"
out.mkdir(parents=True, exist_ok=True)
for t, size in enumerate(SIZES):
    for big in (0, 1):
        for dims in ([2, 2, 2], [3, 2, 4]):
            n = dims[0] * dims[1] * dims[2]
            head = bytes([t | (16 * big)]) + struct.pack("<3I", *dims) + struct.pack("<3f", 1.0, 0.5, 2.0)
            body = bytes((7 * i + 3) % 251 for i in range(n * size))
            name = f"t{t}_{'be' if big else 'le'}_{'x'.join(map(str, dims))}"
            (out / name).write_bytes(head + body)
