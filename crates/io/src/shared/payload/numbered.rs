//! The names of numbered data files (NRRD's and MetaImage's series):
//! printf-style templates and the numbers a range reaches.

/// Expands a printf-style data file name template with one integer
/// conversion (`%d` or `%i`, with flags `-+ 0` and a width; `%%` is a
/// literal `%`), as NRRD's and MetaImage's numbered data files use.
pub(crate) fn format_number(template: &str, value: i64) -> Result<String, String> {
    let mut out = String::new();
    let mut chars = template.chars().peekable();
    let mut converted = false;
    while let Some(c) = chars.next() {
        if c != '%' {
            out.push(c);
            continue;
        }
        if chars.peek() == Some(&'%') {
            chars.next();
            out.push('%');
            continue;
        }
        if converted {
            return Err(format!("\"{template}\" has more than one % conversion"));
        }
        let (mut left, mut zero, mut plus, mut space) = (false, false, false, false);
        while let Some(&f) = chars.peek() {
            match f {
                '-' => left = true,
                '0' => zero = true,
                '+' => plus = true,
                ' ' => space = true,
                _ => break,
            }
            chars.next();
        }
        let mut width = 0usize;
        while let Some(d) = chars.peek().and_then(|c| c.to_digit(10)) {
            width = width.saturating_mul(10).saturating_add(d as usize);
            chars.next();
        }
        if width > 64 {
            return Err(format!("\"{template}\": field width {width} is too large"));
        }
        match chars.next() {
            Some('d' | 'i') => {}
            other => {
                return Err(format!(
                    "\"{template}\": only %d conversions are supported, not %{}",
                    other.map(String::from).unwrap_or_default()
                ));
            }
        }
        let sign = if value < 0 {
            "-"
        } else if plus {
            "+"
        } else if space {
            " "
        } else {
            ""
        };
        let digits = value.unsigned_abs().to_string();
        let len = sign.len() + digits.len();
        let pad = width.saturating_sub(len);
        if left {
            out.push_str(sign);
            out.push_str(&digits);
            out.extend(std::iter::repeat_n(' ', pad));
        } else if zero {
            out.push_str(sign);
            out.extend(std::iter::repeat_n('0', pad));
            out.push_str(&digits);
        } else {
            out.extend(std::iter::repeat_n(' ', pad));
            out.push_str(sign);
            out.push_str(&digits);
        }
        converted = true;
    }
    if !converted {
        return Err(format!("\"{template}\" has no %d conversion"));
    }
    Ok(out)
}

/// Most data files a header may name: bounds the list of names a lying
/// numbered series could make up before any file is opened.
pub(crate) const MAX_FILES: u64 = 1 << 20;

/// How many numbers `min, min + step, ...` reach up to and including
/// `max` (NRRD and MetaImage numbered data files), or `None` if `step` is
/// 0 or points away from `max`.
pub(crate) fn number_range(min: i64, max: i64, step: i64) -> Option<u64> {
    let span = i128::from(max) - i128::from(min);
    if step == 0 || span.signum() * i128::from(step.signum()) < 0 {
        return None;
    }
    u64::try_from(span / i128::from(step)).ok()?.checked_add(1)
}
