"""Writes xz-compressed copies of text fixtures with Python's own lzma
module (liblzma), for crates/io/tests/packed.rs: argv[1] is the output
directory."""
import lzma
import pathlib
import sys

out = pathlib.Path(sys.argv[1])
fixtures = pathlib.Path(__file__).resolve().parent.parent / "fixtures"
for name, source in [
    ("ramp.cube.xz", "cube/ramp_bohr.cube"),
    ("CHGCAR.xz", "chgcar/CHGCAR_ortho"),
]:
    (out / name).write_bytes(lzma.compress((fixtures / source).read_bytes()))
