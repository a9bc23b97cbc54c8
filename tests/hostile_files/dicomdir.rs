//! A DICOM file-set as a CD holds it (`dicom/cd`: a DICOMDIR and two
//! series below it) with its DICOMDIR cut, its record offsets pointing
//! nowhere or in a loop, a listed file missing, and a series asked for
//! that it lacks.

use super::*;

/// The files of `dicom/cd`, as (path under the case, bytes).
fn cd_files() -> Vec<(String, Vec<u8>)> {
    let root = Path::new(FIXTURES).join("dicom");
    let mut files = Vec::new();
    let mut dirs = vec![root.join("cd")];
    while let Some(d) = dirs.pop() {
        for e in fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else {
                let rel = p
                    .strip_prefix(&root)
                    .unwrap()
                    .to_string_lossy()
                    .into_owned();
                files.push((rel, fs::read(&p).unwrap()));
            }
        }
    }
    files.sort();
    files
}

/// The files of `dicom/cd` with its DICOMDIR's bytes `edit`ed.
fn with_dicomdir(
    files: &[(String, Vec<u8>)],
    edit: impl Fn(&[u8]) -> Vec<u8>,
) -> Vec<(String, Vec<u8>)> {
    files
        .iter()
        .map(|(n, b)| {
            let b = if n == "cd/DICOMDIR" {
                edit(b)
            } else {
                b.clone()
            };
            (n.clone(), b)
        })
        .collect()
}

pub(super) fn cases() -> Cases {
    let mut c = Cases::new("dicomdir");
    let files = cd_files();
    let dicomdir = &files
        .iter()
        .find(|(n, _)| n == "cd/DICOMDIR")
        .expect("DICOMDIR")
        .1;
    let n = dicomdir.len();
    c.many("cd/: as written", files.clone(), "cd", Expect::Either);
    c.rendered();
    for (what, at) in [
        ("empty", 0),
        ("cut in the file meta", 140),
        ("cut in the records", n / 2),
        ("one byte short", n - 1),
    ] {
        c.many(
            &format!("cd/DICOMDIR: {what} ({at} of {n} bytes)"),
            with_dicomdir(&files, |b| b[..at].to_vec()),
            "cd",
            Expect::Bad,
        );
    }
    let root_tag = [0x04, 0x00, 0x00, 0x12, b'U', b'L', 4, 0];
    let root = find(dicomdir, &root_tag).expect("root offset") + root_tag.len();
    let next_tag = [0x04, 0x00, 0x00, 0x14, b'U', b'L', 4, 0];
    let next = find(dicomdir, &next_tag).expect("next offset") + next_tag.len();
    let first = dicomdir[root..root + 4].to_vec();
    for (what, at, value) in [
        (
            "root offset past the end",
            root,
            0x7fff_fff0u32.to_le_bytes().to_vec(),
        ),
        (
            "root offset into a record",
            root,
            (u32::from_le_bytes(first[..].try_into().unwrap()) + 8)
                .to_le_bytes()
                .to_vec(),
        ),
        ("first record's next is itself", next, first.clone()),
    ] {
        c.many(
            &format!("cd/DICOMDIR: {what}"),
            with_dicomdir(&files, |b| put(b, at, &value)),
            "cd/DICOMDIR",
            Expect::Bad,
        );
    }
    c.flips("cd/DICOMDIR", dicomdir, n, 6, 43);
    // The flips' cases hold the DICOMDIR alone: give them the series too.
    for case in c.list.iter_mut().filter(|k| k.files.len() == 1) {
        let flipped = case.files[0].1.clone();
        case.files = with_dicomdir(&files, |_| flipped.clone());
        case.input = "cd".into();
    }
    let missing: Vec<_> = files
        .iter()
        .filter(|(n, _)| !n.ends_with("SE000000/IM000002"))
        .cloned()
        .collect();
    assert_eq!(missing.len() + 1, files.len());
    c.many("cd/: a listed image missing", missing, "cd", Expect::Bad);
    c.many("cd/: series 9 of 2", files.clone(), "cd", Expect::Bad);
    c.with_args(&["--series", "9"]);
    c.many("cd/: series by a UID it lacks", files, "cd", Expect::Bad);
    c.with_args(&["--series", "1.2.3.4"]);
    c
}
