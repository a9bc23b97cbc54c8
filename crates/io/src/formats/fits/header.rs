//! FITS headers and HDUs (FITS Standard 4.0, §3 to §4 and §7): 80-byte
//! ASCII cards in 2880-byte blocks up to the END card, each a keyword
//! (bytes 1–8), the value indicator `= ` (bytes 9–10) and a value (a
//! string in single quotes, T or F, an integer, a float with E or D
//! exponent) with an optional `/ comment`; and the size of the data each
//! header announces, which [`next_hdu`] checks against the file before
//! anything is allocated.

use std::path::Path;

use super::source::Source;
use crate::error::IoError;

/// The FITS block: headers and data are padded to whole blocks (§3.1).
pub(super) const BLOCK: usize = 2880;
/// A header card (§4.1).
const CARD: usize = 80;
/// The most cards read while looking for END: real headers hold hundreds
/// to a few thousand; past this a header without END is refused rather
/// than held (8 MB of cards).
const MAX_CARDS: usize = 100_000;

/// A keyword's value (§4.2).
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Value {
    /// No value indicator: COMMENT, HISTORY, CONTINUE, blank keywords.
    None,
    Logical(bool),
    /// Integers keep every digit (BZERO = 9223372036854775808 is 2^63).
    Int(i128),
    Float(f64),
    Str(String),
    /// A complex number, an undefined value, or text that is none of these.
    Other(String),
}

/// One header card.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Card {
    pub key: String,
    pub value: Value,
    /// The value as written (for commentary cards: the text), for `info`.
    pub text: String,
}

/// A header's cards, END excluded.
#[derive(Debug, Clone, Default)]
pub(super) struct Header {
    pub cards: Vec<Card>,
}

impl Header {
    /// The value of the first card with `key`.
    pub fn get(&self, key: &str) -> Option<&Value> {
        self.cards.iter().find(|c| c.key == key).map(|c| &c.value)
    }

    /// An integer keyword; `Err` names the keyword if it holds another value.
    pub fn int(&self, key: &str) -> Result<Option<i128>, String> {
        match self.get(key) {
            None => Ok(None),
            Some(Value::Int(v)) => Ok(Some(*v)),
            Some(Value::Float(v)) if v.fract() == 0.0 && v.abs() < 9e15 => Ok(Some(*v as i128)),
            Some(_) => Err(format!("{key} = {}: not an integer", self.text(key))),
        }
    }

    /// A number (integer or float); `Err` names the keyword if it holds
    /// another value or a non-finite one.
    pub fn float(&self, key: &str) -> Result<Option<f64>, String> {
        let v = match self.get(key) {
            None => return Ok(None),
            Some(Value::Int(v)) => *v as f64,
            Some(Value::Float(v)) => *v,
            Some(_) => return Err(format!("{key} = {}: not a number", self.text(key))),
        };
        if !v.is_finite() {
            return Err(format!("{key} = {}: not a finite number", self.text(key)));
        }
        Ok(Some(v))
    }

    /// A string keyword (its text as written, for another kind of value).
    pub fn string(&self, key: &str) -> Option<String> {
        match self.get(key)? {
            Value::Str(s) => Some(s.clone()),
            Value::None => None,
            _ => Some(self.text(key)),
        }
    }

    pub fn logical(&self, key: &str) -> Option<bool> {
        match self.get(key)? {
            Value::Logical(b) => Some(*b),
            _ => None,
        }
    }

    /// The value of `key` as written.
    pub fn text(&self, key: &str) -> String {
        self.cards
            .iter()
            .find(|c| c.key == key)
            .map_or_else(String::new, |c| c.text.clone())
    }
}

/// What an HDU is (§7): the primary HDU, or an extension by XTENSION.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Kind {
    Primary,
    Image,
    BinTable,
    Other(String),
}

/// One header-and-data unit, as its header describes it.
#[derive(Debug, Clone)]
pub(super) struct Hdu {
    /// 0 for the primary HDU.
    pub index: usize,
    pub kind: Kind,
    pub header: Header,
    pub bitpix: i32,
    /// NAXIS1, NAXIS2, ...: NAXIS1 varies fastest.
    pub naxes: Vec<u64>,
    /// Where the data starts, in the (inflated) file.
    pub data_start: u64,
    /// The data's bytes as §4.4.1 counts them, without the padding to a
    /// whole block.
    pub data_bytes: u128,
}

impl Hdu {
    /// How messages name the HDU: `primary HDU`, `HDU 2 (EXTNAME 'SCI')`.
    pub fn name(&self) -> String {
        match (self.index, self.header.string("EXTNAME")) {
            (0, _) => "primary HDU".into(),
            (i, Some(n)) => format!("HDU {i} (EXTNAME '{}')", n.trim_end()),
            (i, None) => format!("HDU {i}"),
        }
    }

    /// Whether the data is an image: the primary HDU (not random groups)
    /// or an IMAGE extension.
    pub fn is_image(&self) -> bool {
        match self.kind {
            Kind::Primary => self.header.logical("GROUPS") != Some(true),
            Kind::Image => true,
            _ => false,
        }
    }

    /// A tile-compressed image (§10: a BINTABLE with ZIMAGE = T).
    pub fn is_compressed_image(&self) -> bool {
        self.kind == Kind::BinTable && self.header.logical("ZIMAGE") == Some(true)
    }

    /// The data padded to whole blocks.
    pub fn padded_bytes(&self) -> u128 {
        self.data_bytes.div_ceil(BLOCK as u128) * BLOCK as u128
    }
}

/// Reads the next HDU's header from `src` (at a block boundary) and checks
/// the data it declares against the file: `Ok(None)` at the end of the
/// file, or where the bytes that follow the last HDU are not another
/// (§3.5 allows special records there; `trailing` counts them).
pub(super) fn next_hdu(
    path: &Path,
    src: &mut Source,
    index: usize,
    trailing: &mut u64,
) -> Result<Option<Hdu>, IoError> {
    let hdu_name = if index == 0 {
        "primary HDU".to_string()
    } else {
        format!("HDU {index}")
    };
    let bad = |reason: String| IoError::invalid(path, format!("{hdu_name}: {reason}"));
    let mut block = vec![0u8; BLOCK];
    let mut cards = Vec::new();
    let mut ended = false;
    let mut first = true;
    while !ended {
        let got = src.fill_some(path, &mut block, &format!("{hdu_name} header"))?;
        if first && index > 0 && (got == 0 || !block.starts_with(b"XTENSION")) {
            *trailing += got as u64;
            if got > 0 {
                // Count what follows too, without keeping it.
                let mut rest = vec![0u8; BLOCK];
                loop {
                    let n = src.fill_some(path, &mut rest, "bytes after the last HDU")?;
                    *trailing += n as u64;
                    if n < BLOCK {
                        break;
                    }
                }
            }
            return Ok(None);
        }
        if got < BLOCK {
            return Err(bad(format!(
                "the file ends inside the header ({} cards read, no END card)",
                cards.len() + got / CARD
            )));
        }
        if first && index == 0 && !block.starts_with(b"SIMPLE  ") {
            return Err(bad(
                "the first card is not SIMPLE: not a FITS file".to_string()
            ));
        }
        first = false;
        for raw in block.chunks_exact(CARD) {
            if cards.len() >= MAX_CARDS {
                return Err(bad(format!(
                    "no END card in the first {MAX_CARDS} cards of the header"
                )));
            }
            if let Some(at) = raw.iter().position(|b| !(0x20..=0x7e).contains(b)) {
                return Err(bad(format!(
                    "card {} ({}) holds byte 0x{:02x} at column {}: header cards are printable ASCII",
                    cards.len() + 1,
                    printable_key(raw),
                    raw[at],
                    at + 1
                )));
            }
            // Printable ASCII is UTF-8.
            let text = std::str::from_utf8(raw).unwrap_or_default();
            if text[..8].trim_end() == "END" {
                ended = true;
                break;
            }
            cards.push(parse_card(text));
        }
    }
    let header = Header { cards };
    let data_start = src.pos;

    let kind = if index == 0 {
        Kind::Primary
    } else {
        match header.string("XTENSION").as_deref().map(str::trim_end) {
            Some("IMAGE") => Kind::Image,
            Some("BINTABLE") => Kind::BinTable,
            Some(other) => Kind::Other(other.to_string()),
            None => return Err(bad("no XTENSION card".into())),
        }
    };
    let bitpix = header
        .int("BITPIX")
        .map_err(&bad)?
        .ok_or_else(|| bad("no BITPIX card".into()))?;
    if ![8, 16, 32, 64, -32, -64].contains(&bitpix) {
        return Err(bad(format!(
            "BITPIX = {bitpix}: not one of 8, 16, 32, 64, -32, -64"
        )));
    }
    let naxis = header
        .int("NAXIS")
        .map_err(&bad)?
        .ok_or_else(|| bad("no NAXIS card".into()))?;
    if !(0..=999).contains(&naxis) {
        return Err(bad(format!("NAXIS = {naxis}: not from 0 to 999")));
    }
    let mut naxes = Vec::with_capacity(naxis as usize);
    for n in 1..=naxis {
        let key = format!("NAXIS{n}");
        let v = header
            .int(&key)
            .map_err(&bad)?
            .ok_or_else(|| bad(format!("no {key} card (NAXIS = {naxis})")))?;
        let v = u64::try_from(v).map_err(|_| bad(format!("{key} = {v}: not a size")))?;
        naxes.push(v);
    }
    let count = |key: &str, default: i128| -> Result<u128, IoError> {
        let v = header.int(key).map_err(&bad)?.unwrap_or(default);
        u128::try_from(v)
            .ok()
            .filter(|&v| v < 1 << 64)
            .ok_or_else(|| bad(format!("{key} = {v}: not a count")))
    };
    let (pcount, gcount) = (count("PCOUNT", 0)?, count("GCOUNT", 1)?);
    // §4.4.1.1: |BITPIX| · GCOUNT · (PCOUNT + NAXIS1 ··· NAXISm) bits;
    // random groups (NAXIS1 = 0, GROUPS = T) leave out NAXIS1.
    let groups = header.logical("GROUPS") == Some(true) && naxes.first() == Some(&0);
    let axes = if groups { &naxes[1..] } else { &naxes[..] };
    let elements = if axes.is_empty() {
        Some(0)
    } else {
        axes.iter()
            .try_fold(1u128, |acc, &n| acc.checked_mul(u128::from(n)))
    };
    let data_bytes = elements
        .and_then(|e| e.checked_add(pcount))
        .and_then(|e| e.checked_mul(gcount))
        .and_then(|e| e.checked_mul(bitpix.unsigned_abs() / 8))
        .ok_or_else(|| {
            bad(format!(
                "NAXISn {}: more data than any file holds",
                naxes
                    .iter()
                    .map(u64::to_string)
                    .collect::<Vec<_>>()
                    .join(" ")
            ))
        })?;
    let hdu = Hdu {
        index,
        kind,
        header,
        bitpix: bitpix as i32,
        naxes,
        data_start,
        data_bytes,
    };
    // The data must be there: in a plain file, checked now; in a gzip
    // stream, at most what its compressed bytes can inflate to.
    let end = u128::from(data_start) + data_bytes;
    let limit = if src.is_gzip() {
        u128::from(src.file_len) * u128::from(crate::shared::compress::MAX_DEFLATE_RATIO)
    } else {
        u128::from(src.file_len)
    };
    if end > limit {
        let dims: Vec<String> = hdu.naxes.iter().map(u64::to_string).collect();
        return Err(bad(format!(
            "NAXISn {} of BITPIX {bitpix}{} declare {data_bytes} bytes of data from byte {data_start}, but the {} is {} bytes{}",
            dims.join(" "),
            if pcount > 0 || gcount != 1 {
                format!(" (PCOUNT {pcount}, GCOUNT {gcount})")
            } else {
                String::new()
            },
            if src.is_gzip() { "gzip file" } else { "file" },
            src.file_len,
            if src.is_gzip() {
                " and cannot inflate to that much"
            } else {
                ""
            }
        )));
    }
    Ok(Some(hdu))
}

/// The keyword of a card whose bytes may not be text, for messages.
fn printable_key(raw: &[u8]) -> String {
    let key: String = raw[..8]
        .iter()
        .map(|&b| {
            if (0x20..=0x7e).contains(&b) {
                b as char
            } else {
                '?'
            }
        })
        .collect();
    let key = key.trim_end();
    if key.is_empty() {
        "blank keyword".into()
    } else {
        format!("keyword {key}")
    }
}

/// Parses one card of printable ASCII (§4.1, §4.2).
pub(super) fn parse_card(text: &str) -> Card {
    let key = text[..8].trim_end().to_string();
    // ESO's HIERARCH convention: `HIERARCH ESO DET CHIP = value`.
    if key == "HIERARCH"
        && let Some(eq) = text[8..].find('=')
    {
        let name = format!("HIERARCH {}", text[8..8 + eq].trim());
        let (value, written) = parse_value(&text[9 + eq..]);
        return Card {
            key: name,
            value,
            text: written,
        };
    }
    let commentary = matches!(key.as_str(), "COMMENT" | "HISTORY" | "CONTINUE" | "");
    if commentary || &text[8..10] != "= " {
        return Card {
            key,
            value: Value::None,
            text: text[8..].trim().to_string(),
        };
    }
    let (value, written) = parse_value(&text[10..]);
    Card {
        key,
        value,
        text: written,
    }
}

/// A value field (§4.2): the value, and the value as written.
fn parse_value(field: &str) -> (Value, String) {
    let field = field.trim_start();
    if let Some(rest) = field.strip_prefix('\'') {
        // A string: '' is a quote; trailing blanks are not significant.
        let mut s = String::new();
        let mut chars = rest.chars().peekable();
        let mut closed = false;
        while let Some(c) = chars.next() {
            if c == '\'' {
                if chars.peek() == Some(&'\'') {
                    chars.next();
                    s.push('\'');
                } else {
                    closed = true;
                    break;
                }
            } else {
                s.push(c);
            }
        }
        let s = s.trim_end().to_string();
        return if closed {
            (Value::Str(s.clone()), s)
        } else {
            (
                Value::Other(field.trim_end().to_string()),
                field.trim_end().to_string(),
            )
        };
    }
    let written = field.split('/').next().unwrap_or("").trim().to_string();
    let value = match written.as_str() {
        "" => Value::Other(String::new()),
        "T" => Value::Logical(true),
        "F" => Value::Logical(false),
        w => {
            if let Ok(i) = w.parse::<i128>() {
                Value::Int(i)
            } else if let Ok(f) = w.replace(['D', 'd'], "E").parse::<f64>() {
                // Rust reads "inf" and "NaN", FITS does not write them.
                if w.chars().any(|c| c.is_ascii_digit()) {
                    Value::Float(f)
                } else {
                    Value::Other(w.to_string())
                }
            } else {
                Value::Other(w.to_string())
            }
        }
    };
    (value, written)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn card(s: &str) -> Card {
        parse_card(&format!("{s:<80}"))
    }

    #[test]
    fn cards_parse_as_the_standard_writes_them() {
        assert_eq!(card("NAXIS1  =                   12").value, Value::Int(12));
        assert_eq!(
            card("BZERO   =  9223372036854775808").value,
            Value::Int(1 << 63)
        );
        assert_eq!(
            card("CDELT1  = -1.0D-03 / degrees").value,
            Value::Float(-1e-3)
        );
        assert_eq!(
            card("SIMPLE  =                    T").value,
            Value::Logical(true)
        );
        assert_eq!(
            card("CTYPE1  = 'RA---SIN'           / right ascension").value,
            Value::Str("RA---SIN".into())
        );
        assert_eq!(
            card("OBSERVER= 'O''Hara  '").value,
            Value::Str("O'Hara".into())
        );
        assert_eq!(card("COMMENT = not a value").value, Value::None);
        assert_eq!(card("HISTORY written").text, "written");
        let h = card("HIERARCH ESO DET CHIP NX = 2048 / pixels");
        assert_eq!(
            (h.key.as_str(), h.value),
            ("HIERARCH ESO DET CHIP NX", Value::Int(2048))
        );
        assert_eq!(card("BLANK   = NaN").value, Value::Other("NaN".into()));
        assert_eq!(
            card("OBJECT  = 'unclosed").value,
            Value::Other("'unclosed".into())
        );
    }
}
