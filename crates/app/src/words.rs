//! The numbers of command words: the comma-separated lists that the
//! flags (`--range LO,HI`, `--opacity P,Q`) and an overlay's options
//! (`range=LO,HI`, `opacity=P,Q`) read alike. Each parser gives the value
//! or a message saying what is wrong with the text.

/// The comma-separated numbers of `s`, each a `what` (in the message).
pub fn numbers<T: std::str::FromStr>(s: &str, what: &str) -> Result<Vec<T>, String> {
    s.split(',')
        .map(|part| {
            part.trim()
                .parse::<T>()
                .map_err(|_| format!("'{part}' is not a valid {what}"))
        })
        .collect()
}

/// `values`, refused where one is not finite.
pub fn finite(values: Vec<f64>) -> Result<Vec<f64>, String> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(v) => Err(format!("{v} is not a finite number")),
        None => Ok(values),
    }
}

/// Two finite numbers `P,Q`.
pub fn parse_pair(s: &str) -> Result<(f32, f32), String> {
    match finite(numbers::<f64>(s, "number")?)?[..] {
        [p, q] => Ok((p as f32, q as f32)),
        ref v => Err(format!("expected P,Q (two numbers), got {}", v.len())),
    }
}

/// The paper's opacity ramp `p,q`: opacities, `0 <= p < q <= 1`.
pub fn parse_opacity(s: &str) -> Result<(f32, f32), String> {
    match parse_pair(s)? {
        (p, q) if 0.0 <= p && p < q && q <= 1.0 => Ok((p, q)),
        (p, q) => Err(format!("P,Q = {p},{q} needs 0 <= p < q <= 1")),
    }
}

/// A window `LO,HI`: two finite numbers, `LO < HI`.
pub fn parse_range(s: &str) -> Result<(f64, f64), String> {
    match finite(numbers::<f64>(s, "number")?)?[..] {
        [lo, hi] if lo < hi => Ok((lo, hi)),
        [lo, hi] => Err(format!("LO {lo} must be below HI {hi}")),
        ref v => Err(format!("expected LO,HI (two numbers), got {}", v.len())),
    }
}
