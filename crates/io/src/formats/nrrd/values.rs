//! Parsing the values of NRRD header fields that only NRRD has: quoted
//! strings and space vectors `(x,y,z)`, each error naming the field and
//! the value (integers and per-axis lists: [`Field`]).

use std::path::Path;

use super::header::Header;
use crate::error::IoError;
use crate::shared::text_header::Field;

/// The value of a field the format requires.
pub(super) fn required<'h>(
    path: &Path,
    header: &'h Header,
    field: &str,
) -> Result<&'h str, IoError> {
    Field::nrrd(path, field).required(header.get(field))
}

/// A list of `n` double-quoted strings (`units`, `space units`).
pub(super) fn quoted(
    path: &Path,
    field: &str,
    value: &str,
    n: usize,
) -> Result<Vec<String>, IoError> {
    let bad = |why: String| Field::nrrd(path, field).error(why);
    let mut out = Vec::new();
    let mut chars = value.chars().peekable();
    loop {
        while chars.peek().is_some_and(|c| c.is_whitespace()) {
            chars.next();
        }
        match chars.next() {
            None => break,
            Some('"') => {}
            Some(c) => return Err(bad(format!("expected a quoted string, found '{c}'"))),
        }
        let mut s = String::new();
        loop {
            match chars.next() {
                None => return Err(bad("a string has no closing quote".to_string())),
                Some('\\') if chars.peek() == Some(&'"') => s.push(chars.next().unwrap_or('"')),
                Some('"') => break,
                Some(c) => s.push(c),
            }
        }
        out.push(s);
    }
    if out.len() != n {
        return Err(bad(format!("{} strings but {n} are needed", out.len())));
    }
    Ok(out)
}

/// A list of `n` space vectors `(x,y,z)` or `none` (as `None`), each with
/// `sd` coordinates.
pub(super) fn vectors(
    path: &Path,
    field: &str,
    value: &str,
    n: usize,
    sd: usize,
) -> Result<Vec<Option<Vec<f64>>>, IoError> {
    let bad = |why: String| Field::nrrd(path, field).error(why);
    let mut out = Vec::new();
    let mut rest = value.trim_start();
    while !rest.is_empty() {
        if let Some(after) = rest.strip_prefix("none") {
            out.push(None);
            rest = after.trim_start();
            continue;
        }
        let Some(inner) = rest.strip_prefix('(') else {
            return Err(bad(format!(
                "expected \"(\" or none at \"{}\"",
                rest.chars().take(20).collect::<String>()
            )));
        };
        let Some(close) = inner.find(')') else {
            return Err(bad("a vector has no closing \")\"".to_string()));
        };
        let coords: Vec<f64> = inner[..close]
            .split(',')
            .map(|c| {
                c.trim()
                    .parse::<f64>()
                    .map_err(|_| bad(format!("\"{}\" is not a number", c.trim())))
            })
            .collect::<Result<_, _>>()?;
        if coords.len() != sd {
            return Err(bad(format!(
                "a vector has {} coordinates but the space dimension is {sd}",
                coords.len()
            )));
        }
        if coords.iter().any(|c| c.is_infinite()) {
            return Err(bad("a vector coordinate is infinite".to_string()));
        }
        out.push(Some(coords));
        rest = inner[close + 1..].trim_start();
    }
    if out.len() != n {
        return Err(bad(format!("{} vectors but {n} are needed", out.len())));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vector_lists() {
        let p = Path::new("v.nrrd");
        let v = vectors(
            p,
            "space directions",
            "(1,0,0) none ( 0, 2.5 ,0)(0,0,-1)",
            4,
            3,
        )
        .unwrap();
        assert_eq!(v[0], Some(vec![1.0, 0.0, 0.0]));
        assert_eq!(v[1], None);
        assert_eq!(v[2], Some(vec![0.0, 2.5, 0.0]));
        assert_eq!(v[3], Some(vec![0.0, 0.0, -1.0]));
        let err = vectors(p, "space directions", "(1,0) (0,1)", 2, 3).unwrap_err();
        assert!(
            err.to_string()
                .contains("2 coordinates but the space dimension is 3"),
            "{err}"
        );
        let err = vectors(p, "space directions", "(1,0,0)", 3, 3).unwrap_err();
        assert!(
            err.to_string().contains("1 vectors but 3 are needed"),
            "{err}"
        );
        let err = vectors(p, "space origin", "(1,x,0)", 1, 3).unwrap_err();
        assert!(err.to_string().contains("\"x\" is not a number"), "{err}");
        let err = vectors(p, "space origin", "(1,0,0", 1, 3).unwrap_err();
        assert!(err.to_string().contains("no closing"), "{err}");
        let err = vectors(p, "space origin", "(inf,0,0)", 1, 3).unwrap_err();
        assert!(err.to_string().contains("infinite"), "{err}");
    }

    #[test]
    fn quoted_strings() {
        let p = Path::new("v.nrrd");
        assert_eq!(
            quoted(p, "units", r#""mm" "m\"m"  "" "#, 3).unwrap(),
            ["mm", "m\"m", ""]
        );
        assert!(quoted(p, "units", r#""mm" mm"#, 2).is_err());
        assert!(quoted(p, "units", r#""mm"#, 1).is_err());
        assert!(quoted(p, "units", r#""mm""#, 2).is_err());
    }
}
