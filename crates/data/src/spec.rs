//! Source specs: `NAME[:ARG[,ARG...]]`, each `ARG` a bare positional value or
//! `key=value`, and typed access to their arguments.

use std::fmt;
use std::str::FromStr;

use crate::DataError;

/// A parsed source spec such as `marschner-lobb:41,fm=6`.
///
/// Parsing only checks the grammar; whether the name is a registered source
/// and whether its arguments make sense is up to [`generate`](crate::generate)
/// and the source (through [`Args`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SourceSpec {
    /// The source name, before the first `:`.
    pub name: String,
    /// Bare arguments, in order; they all come before the named ones.
    pub positional: Vec<String>,
    /// `key=value` arguments, in order, keys unique.
    pub named: Vec<(String, String)>,
}

impl SourceSpec {
    /// Parses `NAME[:ARG[,ARG...]]`.
    ///
    /// Whitespace around the name, the arguments, keys and values is ignored.
    /// Errors: an empty spec or name, an empty argument (`a:1,,2`, `a:1,`,
    /// `a:`), an empty key or value (`=1`, `k=`), a positional argument after
    /// a named one, a key given twice.
    pub fn parse(s: &str) -> Result<SourceSpec, DataError> {
        let text = s.trim();
        if text.is_empty() {
            return Err(DataError::EmptySpec);
        }
        let spec = || text.to_string();
        let (name, args) = match text.split_once(':') {
            Some((name, args)) => (name.trim(), Some(args)),
            None => (text, None),
        };
        if name.is_empty() {
            return Err(DataError::EmptyName { spec: spec() });
        }
        let mut positional = Vec::new();
        let mut named: Vec<(String, String)> = Vec::new();
        for (i, arg) in args.into_iter().flat_map(|a| a.split(',')).enumerate() {
            let arg = arg.trim();
            if arg.is_empty() {
                return Err(DataError::EmptyArg {
                    spec: spec(),
                    position: i + 1,
                });
            }
            match arg.split_once('=') {
                Some((key, value)) => {
                    let (key, value) = (key.trim(), value.trim());
                    if key.is_empty() {
                        return Err(DataError::EmptyKey {
                            spec: spec(),
                            arg: arg.to_string(),
                        });
                    }
                    if value.is_empty() {
                        return Err(DataError::EmptyValue {
                            spec: spec(),
                            arg: arg.to_string(),
                        });
                    }
                    if named.iter().any(|(k, _)| k == key) {
                        return Err(DataError::DuplicateKey {
                            spec: spec(),
                            key: key.to_string(),
                        });
                    }
                    named.push((key.to_string(), value.to_string()));
                }
                None => {
                    if !named.is_empty() {
                        return Err(DataError::PositionalAfterNamed {
                            spec: spec(),
                            arg: arg.to_string(),
                        });
                    }
                    positional.push(arg.to_string());
                }
            }
        }
        Ok(SourceSpec {
            name: name.to_string(),
            positional,
            named,
        })
    }

    /// The value of `key=value`, if given.
    pub fn named(&self, key: &str) -> Option<&str> {
        self.named
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
}

impl FromStr for SourceSpec {
    type Err = DataError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        SourceSpec::parse(s)
    }
}

/// The canonical form, `name:p1,p2,k1=v1,k2=v2`, which parses back to the
/// same spec. Error messages name specs in this form.
impl fmt::Display for SourceSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name)?;
        let mut sep = ':';
        for p in &self.positional {
            write!(f, "{sep}{p}")?;
            sep = ',';
        }
        for (k, v) in &self.named {
            write!(f, "{sep}{k}={v}")?;
            sep = ',';
        }
        Ok(())
    }
}

/// A source's view of a spec's arguments: which parameters it takes, and
/// typed access to them.
///
/// [`Args::new`] rejects every key the source does not take and every surplus
/// positional argument, so a typo is never silently ignored. Parameters listed
/// as positional may also be given by name (`marschner-lobb:41` or
/// `marschner-lobb:n=41`), but not both ways at once.
#[derive(Debug, Clone, Copy)]
pub struct Args<'a> {
    spec: &'a SourceSpec,
    positional_keys: &'a [&'a str],
}

impl<'a> Args<'a> {
    /// Checks `spec`'s arguments against a source taking `positional_keys`
    /// (in order, each also accepted as `key=value`) and `named_keys` (only
    /// as `key=value`).
    pub fn new(
        spec: &'a SourceSpec,
        positional_keys: &'a [&'a str],
        named_keys: &[&str],
    ) -> Result<Self, DataError> {
        if let Some(value) = spec.positional.get(positional_keys.len()) {
            return Err(DataError::SurplusPositional {
                spec: spec.to_string(),
                source_name: spec.name.clone(),
                value: value.clone(),
                max: positional_keys.len(),
                keys: positional_keys.join(", "),
            });
        }
        for (key, _) in &spec.named {
            let key = key.as_str();
            match positional_keys.iter().position(|k| *k == key) {
                Some(i) if i < spec.positional.len() => {
                    return Err(DataError::GivenTwice {
                        spec: spec.to_string(),
                        key: key.to_string(),
                    });
                }
                Some(_) => {}
                None if named_keys.contains(&key) => {}
                None => {
                    let allowed: Vec<&str> =
                        positional_keys.iter().chain(named_keys).copied().collect();
                    let allowed = if allowed.is_empty() {
                        "no parameters".to_string()
                    } else {
                        allowed.join(", ")
                    };
                    return Err(DataError::UnknownKey {
                        spec: spec.to_string(),
                        source_name: spec.name.clone(),
                        key: key.to_string(),
                        allowed,
                    });
                }
            }
        }
        Ok(Args {
            spec,
            positional_keys,
        })
    }

    /// The spec these arguments come from.
    pub fn spec(&self) -> &'a SourceSpec {
        self.spec
    }

    /// The raw value of positional argument `index`, or else of `key=value`.
    pub fn positional_or_named(&self, index: usize, key: &str) -> Option<&'a str> {
        match self.spec.positional.get(index) {
            Some(v) => Some(v.as_str()),
            None => self.spec.named(key),
        }
    }

    /// The raw value of parameter `key`, given by position (if `key` is one of
    /// the positional keys) or by name.
    pub fn get(&self, key: &str) -> Option<&'a str> {
        match self.positional_keys.iter().position(|k| *k == key) {
            Some(i) => self.positional_or_named(i, key),
            None => self.spec.named(key),
        }
    }

    fn parse<T: FromStr>(&self, key: &str, expected: &'static str) -> Result<Option<T>, DataError> {
        self.get(key)
            .map(|value| {
                value.parse().map_err(|_| DataError::BadValue {
                    spec: self.spec.to_string(),
                    key: key.to_string(),
                    value: value.to_string(),
                    expected,
                })
            })
            .transpose()
    }

    /// Parameter `key` as a non-negative integer, if given.
    pub fn usize(&self, key: &str) -> Result<Option<usize>, DataError> {
        self.parse(key, "a non-negative integer")
    }

    /// Parameter `key` as a non-negative integer, or `default`.
    pub fn usize_or(&self, key: &str, default: usize) -> Result<usize, DataError> {
        Ok(self.usize(key)?.unwrap_or(default))
    }

    /// Parameter `key` as a 64-bit unsigned integer (e.g. a seed), if given.
    pub fn u64(&self, key: &str) -> Result<Option<u64>, DataError> {
        self.parse(key, "a non-negative integer")
    }

    /// Parameter `key` as a signed integer, if given.
    pub fn i64(&self, key: &str) -> Result<Option<i64>, DataError> {
        self.parse(key, "an integer")
    }

    /// Parameter `key` as a finite number, if given (`nan` and `inf` are
    /// rejected).
    pub fn f64(&self, key: &str) -> Result<Option<f64>, DataError> {
        const EXPECTED: &str = "a finite number";
        match self.parse::<f64>(key, EXPECTED)? {
            Some(v) if !v.is_finite() => Err(DataError::BadValue {
                spec: self.spec.to_string(),
                key: key.to_string(),
                value: self.get(key).unwrap_or_default().to_string(),
                expected: EXPECTED,
            }),
            v => Ok(v),
        }
    }

    /// Parameter `key` as a finite number, or `default`.
    pub fn f64_or(&self, key: &str, default: f64) -> Result<f64, DataError> {
        Ok(self.f64(key)?.unwrap_or(default))
    }

    /// Parameter `key` as a boolean, `true` or `false` exactly, if given.
    pub fn bool(&self, key: &str) -> Result<Option<bool>, DataError> {
        self.parse(key, "true or false")
    }

    /// Parameter `key` as a boolean (`true` or `false`), or `default`.
    pub fn bool_or(&self, key: &str, default: bool) -> Result<bool, DataError> {
        Ok(self.bool(key)?.unwrap_or(default))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &str) -> SourceSpec {
        SourceSpec::parse(s).unwrap_or_else(|e| panic!("{s}: {e}"))
    }

    fn strs(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn parses_good_specs() {
        assert_eq!(
            parse("marschner-lobb"),
            SourceSpec {
                name: "marschner-lobb".into(),
                positional: vec![],
                named: vec![]
            }
        );
        assert_eq!(
            parse("marschner-lobb:41"),
            SourceSpec {
                name: "marschner-lobb".into(),
                positional: strs(&["41"]),
                named: vec![]
            }
        );
        let s = parse("hydrogen:6,2,1,grid=50,extent=40");
        assert_eq!(s.name, "hydrogen");
        assert_eq!(s.positional, strs(&["6", "2", "1"]));
        assert_eq!(
            s.named,
            vec![
                ("grid".to_string(), "50".to_string()),
                ("extent".to_string(), "40".to_string())
            ]
        );
        assert_eq!(s.named("extent"), Some("40"));
        assert_eq!(s.named("seed"), None);
        let s = parse("fractal:fm=6,dim=3.7");
        assert!(s.positional.is_empty());
        assert_eq!(s.named("dim"), Some("3.7"));
        // Whitespace around the pieces is ignored.
        assert_eq!(
            parse("  sphere : 33 , radius = 0.5 "),
            parse("sphere:33,radius=0.5")
        );
        // A value may hold '=' (it is the source's job to reject it).
        assert_eq!(parse("x:k=a=b").named("k"), Some("a=b"));
    }

    #[test]
    fn display_is_canonical_and_round_trips() {
        for s in [
            "blobs",
            "marschner-lobb:41",
            "hydrogen:6,2,1,grid=50,extent=40",
            "a:k=v",
        ] {
            assert_eq!(parse(s).to_string(), s);
            assert_eq!(parse(&parse(s).to_string()), parse(s));
        }
        assert_eq!(parse(" a : 1 , k = v ").to_string(), "a:1,k=v");
        assert_eq!("a:1".parse::<SourceSpec>().unwrap(), parse("a:1"));
    }

    #[test]
    fn rejects_bad_grammar() {
        let err = |s: &str| SourceSpec::parse(s).unwrap_err();
        assert_eq!(err(""), DataError::EmptySpec);
        assert_eq!(err("   "), DataError::EmptySpec);
        assert!(matches!(err(":41"), DataError::EmptyName { .. }));
        assert_eq!(
            err("a:1,,2"),
            DataError::EmptyArg {
                spec: "a:1,,2".into(),
                position: 2
            }
        );
        assert!(matches!(
            err("a:1,"),
            DataError::EmptyArg { position: 2, .. }
        ));
        assert!(matches!(err("a:"), DataError::EmptyArg { position: 1, .. }));
        assert!(matches!(
            err("a:1, ,2"),
            DataError::EmptyArg { position: 2, .. }
        ));
        assert!(matches!(err("a:=3"), DataError::EmptyKey { .. }));
        assert!(matches!(err("a:k="), DataError::EmptyValue { .. }));
        assert_eq!(
            err("a:k=1,2"),
            DataError::PositionalAfterNamed {
                spec: "a:k=1,2".into(),
                arg: "2".into()
            }
        );
        assert_eq!(
            err("a:k=1,j=2,k=3"),
            DataError::DuplicateKey {
                spec: "a:k=1,j=2,k=3".into(),
                key: "k".into()
            }
        );
        assert_eq!(
            err("a:k=1,2").to_string(),
            "a:k=1,2: positional argument `2` comes after a named one; put positional arguments first"
        );
        assert_eq!(err("a:1,,2").to_string(), "a:1,,2: argument 2 is empty");
    }

    #[test]
    fn args_resolve_positional_and_named() {
        let s = parse("src:41,fm=6.5");
        let a = Args::new(&s, &["n"], &["fm", "alpha"]).unwrap();
        assert_eq!(a.get("n"), Some("41"));
        assert_eq!(a.positional_or_named(0, "n"), Some("41"));
        assert_eq!(a.usize_or("n", 3).unwrap(), 41);
        assert_eq!(a.f64_or("fm", 1.0).unwrap(), 6.5);
        assert_eq!(a.f64_or("alpha", 0.25).unwrap(), 0.25);
        assert_eq!(a.f64("alpha").unwrap(), None);

        let s = parse("src:n=17,alpha=-2");
        let a = Args::new(&s, &["n"], &["fm", "alpha"]).unwrap();
        assert_eq!(a.usize("n").unwrap(), Some(17));
        assert_eq!(a.i64("alpha").unwrap(), Some(-2));
        assert_eq!(a.positional_or_named(0, "n"), Some("17"));

        let s = parse("src:6,2,-1,seed=18446744073709551615");
        let a = Args::new(&s, &["n", "l", "m"], &["seed"]).unwrap();
        assert_eq!(a.i64("m").unwrap(), Some(-1));
        assert_eq!(a.u64("seed").unwrap(), Some(u64::MAX));
    }

    #[test]
    fn args_read_booleans_exactly() {
        let s = parse("src:real=true,flag=false,bad=yes,caps=True");
        let a = Args::new(&s, &[], &["real", "flag", "bad", "caps", "unset"]).unwrap();
        assert_eq!(a.bool("real").unwrap(), Some(true));
        assert_eq!(a.bool("flag").unwrap(), Some(false));
        assert_eq!(a.bool("unset").unwrap(), None);
        assert!(a.bool_or("unset", true).unwrap());
        assert!(!a.bool_or("flag", true).unwrap());
        assert_eq!(
            a.bool("bad").unwrap_err().to_string(),
            "src:real=true,flag=false,bad=yes,caps=True: bad must be true or false, got `yes`"
        );
        assert!(a.bool_or("caps", false).is_err());
    }

    #[test]
    fn args_reject_unknown_surplus_and_twice() {
        let s = parse("src:41,fn=6");
        let e = Args::new(&s, &["n"], &["fm", "alpha"]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "src:41,fn=6: unknown parameter `fn`; src takes n, fm, alpha"
        );

        let s = parse("src:41,3");
        let e = Args::new(&s, &["n"], &["fm"]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "src:41,3: surplus positional argument `3`; src takes at most 1 (n)"
        );
        let s = parse("src:1");
        assert!(matches!(
            Args::new(&s, &[], &[]).unwrap_err(),
            DataError::SurplusPositional { max: 0, .. }
        ));
        let s = parse("src:k=1");
        assert!(
            Args::new(&s, &[], &[])
                .unwrap_err()
                .to_string()
                .ends_with("src takes no parameters")
        );

        let s = parse("src:41,n=33");
        assert_eq!(
            Args::new(&s, &["n"], &[]).unwrap_err(),
            DataError::GivenTwice {
                spec: "src:41,n=33".into(),
                key: "n".into()
            }
        );
    }

    #[test]
    fn args_reject_bad_numbers() {
        let s = parse("src:4x,fm=abc,alpha=nan,beta=inf,gamma=-3");
        let a = Args::new(&s, &["n"], &["fm", "alpha", "beta", "gamma"]).unwrap();
        assert_eq!(
            a.usize("n").unwrap_err().to_string(),
            "src:4x,fm=abc,alpha=nan,beta=inf,gamma=-3: n must be a non-negative integer, got `4x`"
        );
        assert_eq!(
            a.f64("fm").unwrap_err(),
            DataError::BadValue {
                spec: s.to_string(),
                key: "fm".into(),
                value: "abc".into(),
                expected: "a finite number"
            }
        );
        assert!(matches!(a.f64("alpha"), Err(DataError::BadValue { .. })));
        assert!(matches!(a.f64("beta"), Err(DataError::BadValue { .. })));
        assert!(matches!(a.usize("gamma"), Err(DataError::BadValue { .. })));
        assert_eq!(a.f64("gamma").unwrap(), Some(-3.0));
        assert!(a.i64("fm").is_err());
    }
}
