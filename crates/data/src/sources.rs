//! The registry of built-in sources and the dispatch from a spec to its
//! generator.

use volray_core::Volume;

use crate::{DataError, SourceSpec, blobs, fractal, hydrogen, marschner_lobb, sphere, torus};

/// A built-in source: its name, usage line and one-line description, and the
/// generator behind it.
#[derive(Debug, Clone, Copy)]
pub struct SourceInfo {
    /// The name a spec starts with, e.g. `marschner-lobb`.
    pub name: &'static str,
    /// The spec grammar, e.g. `marschner-lobb[:N][,fm=F][,alpha=A]`.
    pub usage: &'static str,
    /// What the volume is, with its defaults.
    pub description: &'static str,
    /// Makes the volume from a spec whose name is `name`.
    pub(crate) build: fn(&SourceSpec) -> Result<Volume, DataError>,
}

impl SourceInfo {
    /// Generates this source's volume from a parsed spec (whose name is not
    /// checked: use [`generate`] to dispatch by name).
    pub fn generate(&self, spec: &SourceSpec) -> Result<Volume, DataError> {
        (self.build)(spec)
    }
}

/// Every built-in source, in the order help text lists them.
/// To add a source, add its module and its `INFO` here.
static SOURCES: &[SourceInfo] = &[
    marschner_lobb::INFO,
    blobs::INFO,
    sphere::INFO,
    torus::INFO,
    hydrogen::INFO,
    fractal::INFO,
];

/// The built-in sources.
pub fn sources() -> &'static [SourceInfo] {
    SOURCES
}

/// The source registered as `name` (exact, case-sensitive match).
pub fn find(name: &str) -> Option<&'static SourceInfo> {
    SOURCES.iter().find(|s| s.name == name)
}

/// Whether `s` names a built-in source rather than a file: true iff the part
/// before the first `:` (or all of `s`), trimmed, is a registered name.
///
/// `marschner-lobb` and `marschner-lobb:41` are specs; `data.raw`,
/// `./marschner-lobb` and `C:\x.raw` are not. The spec itself may still be
/// malformed: [`generate`] reports that.
pub fn is_source_spec(s: &str) -> bool {
    let name = s.split_once(':').map_or(s, |(name, _)| name);
    find(name.trim()).is_some()
}

/// Parses `spec` and generates the volume of the source it names.
///
/// Errors: a malformed spec, an unknown source name (the message lists the
/// known ones), or arguments the source rejects.
pub fn generate(spec: &str) -> Result<Volume, DataError> {
    let parsed = SourceSpec::parse(spec)?;
    let source = find(&parsed.name).ok_or_else(|| DataError::UnknownSource {
        spec: parsed.to_string(),
        name: parsed.name.clone(),
        known: SOURCES
            .iter()
            .map(|s| s.name)
            .collect::<Vec<_>>()
            .join(", "),
    })?;
    source.generate(&parsed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn registry_is_consistent() {
        let names: Vec<&str> = sources().iter().map(|s| s.name).collect();
        assert_eq!(
            names,
            [
                "marschner-lobb",
                "blobs",
                "sphere",
                "torus",
                "hydrogen",
                "fractal"
            ]
        );
        for (i, s) in sources().iter().enumerate() {
            assert!(!names[..i].contains(&s.name), "duplicate name {}", s.name);
            assert!(s.usage.starts_with(s.name), "{}", s.usage);
            assert!(!s.description.is_empty() && !s.description.contains('\n'));
            // Names must not be confusable with paths or the spec syntax.
            assert!(
                s.name
                    .chars()
                    .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
            );
            assert!(std::ptr::eq(find(s.name).unwrap(), s));
        }
    }

    #[test]
    fn every_source_generates_a_small_grid_by_name() {
        for s in sources() {
            // hydrogen's positional arguments are quantum numbers, not the grid.
            if s.name == "hydrogen" {
                continue;
            }
            let v = generate(&format!("{}:5", s.name)).unwrap();
            assert_eq!(v.dims(), [5, 5, 5], "{}", s.name);
            assert_eq!(v.count_non_finite(), 0, "{}", s.name);
            let (lo, hi) = v.value_range().unwrap();
            assert!(lo >= 0.0 && hi <= 1.1 && hi > lo, "{}: {lo}..{hi}", s.name);
            // Too small a grid is rejected by every source, naming the spec.
            let e = generate(&format!("{}:1", s.name)).unwrap_err();
            assert_eq!(
                e.to_string(),
                format!(
                    "{}:1: grid must have at least 2 points per side, got 1",
                    s.name
                )
            );
            let e = generate(&format!("{}:5,bogus=1", s.name)).unwrap_err();
            assert!(matches!(e, DataError::UnknownKey { .. }), "{e}");
        }
    }

    #[test]
    fn recognises_specs_and_not_paths() {
        for s in [
            "marschner-lobb",
            "marschner-lobb:41",
            "marschner-lobb:41,fm=6",
            "marschner-lobb:",
            "blobs",
            "sphere:9,radius=0.5",
            "torus",
        ] {
            assert!(is_source_spec(s), "{s}");
        }
        for s in [
            "data.raw",
            "./marschner-lobb",
            "C:\\x.raw",
            "C:/x.raw",
            "marschner-lobb.raw",
            "Marschner-Lobb",
            "dir/sphere:9",
            "",
            ":41",
            "nosuch:6,2,1",
        ] {
            assert!(!is_source_spec(s), "{s}");
        }
    }

    #[test]
    fn unknown_source_lists_the_known_ones() {
        let e = generate("marschner:41").unwrap_err();
        assert_eq!(
            e.to_string(),
            "marschner:41: unknown source `marschner`; known sources: marschner-lobb, blobs, sphere, torus, hydrogen, fractal"
        );
        assert!(matches!(generate(""), Err(DataError::EmptySpec)));
        assert!(matches!(
            generate("sphere:9,,radius=0.5"),
            Err(DataError::EmptyArg { .. })
        ));
    }
}
