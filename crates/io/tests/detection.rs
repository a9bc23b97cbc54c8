//! Formats known by their content, whatever the file's name: VASP files
//! renamed (`Li_CHG`, `density.dat`), cube files and CCP4/MRC maps
//! without their extension; and no false alarms on the other formats'
//! fixtures or on random bytes.

mod common;

use std::fs;
use std::path::{Path, PathBuf};

use volray_io::{ReadOptions, VolumeFormat, read};

fn fixtures() -> PathBuf {
    common::fixture("", "")
}

/// Every fixture file, recursively, with the folder it is in.
fn every_fixture() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else {
                out.push(path);
            }
        }
    }
    let mut out = Vec::new();
    walk(&fixtures(), &mut out);
    out.sort();
    out
}

/// What the first 1024 bytes of `path` show.
fn sniffed(path: &Path) -> Option<VolumeFormat> {
    let bytes = fs::read(path).unwrap();
    VolumeFormat::sniff(&bytes[..bytes.len().min(1024)])
}

/// `rel` copied to `name` in `dir`, read without naming the format.
fn read_renamed(dir: &Path, rel: &str, name: &str) -> volray_io::Loaded {
    let to = dir.join(name);
    fs::copy(fixtures().join(rel), &to).unwrap();
    read(&to, &ReadOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn renamed_vasp_cube_and_mrc_files_are_read_by_content() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (rel, name) in [
        ("chgcar/CHGCAR_ortho", "Li_CHG"),
        ("chgcar/CHGCAR_spin", "density.dat"),
        ("chgcar/CHGCAR_vasp4", "run7_density"),
        ("chgcar/CHG_hexagonal", "graphene"),
        ("chgcar/LOCPOT", "Li_LOCPOT"),
    ] {
        let l = read_renamed(d, rel, name);
        assert_eq!(l.format, VolumeFormat::Chgcar, "{rel} as {name}");
        let direct = read(&fixtures().join(rel), &ReadOptions::default()).unwrap();
        assert_eq!(l.volume, direct.volume, "{rel} as {name}");
    }
    // A LOCPOT whose name does not say so is read as a charge file, and
    // told.
    let l = read_renamed(d, "chgcar/LOCPOT", "potential.txt");
    assert_eq!(l.format, VolumeFormat::Chgcar);
    assert!(
        l.info
            .notes
            .iter()
            .any(|n| n.contains("known as VASP by its content")),
        "{:?}",
        l.info.notes
    );
    for (rel, name) in [
        ("cube/ramp_bohr.cube", "orbital.txt"),
        ("cube/hexagonal.cube", "density"),
        ("cube/orbitals_angstrom.cube", "homo.dat"),
    ] {
        assert_eq!(
            read_renamed(d, rel, name).format,
            VolumeFormat::Cube,
            "{rel}"
        );
    }
    for (rel, name) in [
        ("mrc/mode2_f32.mrc", "emd_1234"),
        ("mrc/hexagonal.ccp4", "2fofc.bin"),
    ] {
        assert_eq!(
            read_renamed(d, rel, name).format,
            VolumeFormat::Mrc,
            "{rel}"
        );
    }
}

#[test]
fn every_fixture_is_sniffed_as_its_own_format_or_not_at_all() {
    let text_formats = [VolumeFormat::Cube, VolumeFormat::Chgcar];
    let mut checked = 0;
    for path in every_fixture() {
        let folder = path
            .parent()
            .unwrap()
            .file_name()
            .unwrap()
            .to_string_lossy();
        let got = sniffed(&path);
        let own = match folder.as_ref() {
            "cube" => Some(VolumeFormat::Cube),
            "chgcar" => Some(VolumeFormat::Chgcar),
            _ => None,
        };
        match own {
            Some(f) => assert_eq!(got, Some(f), "{}", path.display()),
            None => assert!(
                !got.is_some_and(|g| text_formats.contains(&g)),
                "{} sniffed as {got:?}",
                path.display()
            ),
        }
        checked += 1;
    }
    assert!(checked > 100, "{checked} fixtures");
}

#[test]
fn random_bytes_and_near_misses_are_no_text_format() {
    // xorshift: reproducible noise, binary and ASCII digits.
    let mut s = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    };
    for n in 0..2000 {
        let bytes: Vec<u8> = if n % 2 == 0 {
            (0..1024).map(|_| next() as u8).collect()
        } else {
            // Digits, spaces, dots and newlines: text that is all numbers.
            let alphabet = b"0123456789 .-\n\n ";
            (0..1024)
                .map(|_| alphabet[(next() % alphabet.len() as u64) as usize])
                .collect()
        };
        let got = VolumeFormat::sniff(&bytes);
        assert!(
            !matches!(got, Some(VolumeFormat::Cube | VolumeFormat::Chgcar)),
            "noise {n} sniffed as {got:?}"
        );
    }
    // A POSCAR without its coordinate kind, a cube header cut before its
    // third axis, a table of four numbers a line: none of them.
    for text in [
        "Si\n1.0\n5 0 0\n0 5 0\n0 0 5\nSi\n2\n",
        "Si\n1.0\n5 0 0\n0 5 0\n0 0 5\nSi\n2\nnonsense\n0 0 0\n",
        "c1\nc2\n2 0 0 0\n10 0.1 0 0\n10 0 0.1 0\n",
        "x y z w\n1 2 3 4\n1 2 3 4\n1 2 3 4\n1 2 3 4\n1 2 3 4\n1 2 3 4\n1 2 3 4\n",
        "a\nb\n1 0 0 0\n1 0 0 0\n1 0 0 0\n1 0 0 0\n",
    ] {
        assert_eq!(VolumeFormat::sniff(text.as_bytes()), None, "{text:?}");
    }
    // A POSCAR whose window ends in the atom lines is enough.
    let poscar = "Li bcc\n3.44\n1 0 0\n0 1 0\n0 0 1\nLi\n2\nDirect\n0 0 0\n0.5 0.5";
    assert_eq!(
        VolumeFormat::sniff(poscar.as_bytes()),
        Some(VolumeFormat::Chgcar)
    );
}
