//! The Python literals a `.npy` header is written in (strings, integers,
//! booleans, `None`, tuples, lists and dicts), read by a recursive-descent
//! parser bounded in depth.

use std::fmt::Write as _;

/// Deepest nesting of brackets the header parser follows.
const MAX_DEPTH: usize = 16;

/// Header text quoted in a message: one line, at most 80 characters.
pub(super) fn snippet(s: &str) -> String {
    let one_line: String = s
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    if one_line.chars().count() > 80 {
        let mut t: String = one_line.chars().take(77).collect();
        t.push_str("...");
        t
    } else {
        one_line
    }
}

/// A Python literal, as far as `.npy` headers use them.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Lit {
    Str(String),
    Int(i128),
    Bool(bool),
    None,
    Tuple(Vec<Lit>),
    List(Vec<Lit>),
    /// Entries with the byte span of each value's source text.
    Dict(Vec<(Lit, Lit, (usize, usize))>),
}

/// A recursive-descent parser of Python literals, bounded in depth.
pub(super) struct Parser<'a> {
    pub(super) src: &'a [u8],
    pub(super) pos: usize,
}

impl Parser<'_> {
    pub(super) fn skip_ws(&mut self) {
        while self
            .src
            .get(self.pos)
            .is_some_and(|c| c.is_ascii_whitespace())
        {
            self.pos += 1;
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip_ws();
        self.src.get(self.pos).copied()
    }

    fn fail<T>(&self, what: &str) -> Result<T, String> {
        let mut msg = format!(".npy header is malformed: {what} at byte {}", self.pos);
        if let Some(&c) = self.src.get(self.pos) {
            let _ = write!(msg, " ('{}')", snippet(&char::from(c).to_string()));
        }
        Err(msg)
    }

    fn expect(&mut self, c: u8) -> Result<(), String> {
        if self.peek() == Some(c) {
            self.pos += 1;
            Ok(())
        } else {
            self.fail(&format!("expected '{}'", char::from(c)))
        }
    }

    /// Parses one value; returns it with the byte span of its source text.
    pub(super) fn value(&mut self, depth: usize) -> Result<(Lit, (usize, usize)), String> {
        if depth > MAX_DEPTH {
            return self.fail("nesting too deep");
        }
        let start = {
            self.skip_ws();
            self.pos
        };
        let lit = match self.peek() {
            None => return self.fail("unexpected end"),
            Some(b'{') => {
                self.pos += 1;
                let mut entries = Vec::new();
                loop {
                    if self.peek() == Some(b'}') {
                        self.pos += 1;
                        break;
                    }
                    let (key, _) = self.value(depth + 1)?;
                    self.expect(b':')?;
                    let (value, span) = self.value(depth + 1)?;
                    entries.push((key, value, span));
                    match self.peek() {
                        Some(b',') => self.pos += 1,
                        Some(b'}') => {}
                        _ => return self.fail("expected ',' or '}'"),
                    }
                }
                Lit::Dict(entries)
            }
            Some(open @ (b'(' | b'[')) => {
                let close = if open == b'(' { b')' } else { b']' };
                self.pos += 1;
                let mut items = Vec::new();
                let mut trailing_comma = false;
                loop {
                    if self.peek() == Some(close) {
                        self.pos += 1;
                        break;
                    }
                    items.push(self.value(depth + 1)?.0);
                    trailing_comma = false;
                    match self.peek() {
                        Some(b',') => {
                            self.pos += 1;
                            trailing_comma = true;
                        }
                        Some(c) if c == close => {}
                        _ => return self.fail("expected ',' or a closing bracket"),
                    }
                }
                if open == b'[' {
                    Lit::List(items)
                } else if items.len() == 1 && !trailing_comma {
                    // "(x)" is just x in Python.
                    items.pop().unwrap_or(Lit::None)
                } else {
                    Lit::Tuple(items)
                }
            }
            Some(q @ (b'\'' | b'"')) => {
                self.pos += 1;
                let mut bytes = Vec::new();
                loop {
                    match self.src.get(self.pos) {
                        None => return self.fail("unterminated string"),
                        Some(&c) if c == q => {
                            self.pos += 1;
                            break;
                        }
                        Some(b'\\') => {
                            let Some(&e) = self.src.get(self.pos + 1) else {
                                return self.fail("unterminated string");
                            };
                            bytes.push(e);
                            self.pos += 2;
                        }
                        Some(&c) => {
                            bytes.push(c);
                            self.pos += 1;
                        }
                    }
                }
                Lit::Str(String::from_utf8_lossy(&bytes).into_owned())
            }
            Some(c) if c.is_ascii_digit() || c == b'-' || c == b'+' => {
                let s = self.pos;
                self.pos += 1;
                while self.src.get(self.pos).is_some_and(u8::is_ascii_digit) {
                    self.pos += 1;
                }
                let digits = std::str::from_utf8(&self.src[s..self.pos]).unwrap_or("");
                let n = digits
                    .parse::<i128>()
                    .or_else(|_| self.fail("bad integer"))?;
                // Python 2 wrote long integers as "3L".
                if matches!(self.src.get(self.pos), Some(b'L' | b'l')) {
                    self.pos += 1;
                }
                Lit::Int(n)
            }
            Some(c) if c.is_ascii_alphabetic() || c == b'_' => {
                let s = self.pos;
                while self
                    .src
                    .get(self.pos)
                    .is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_')
                {
                    self.pos += 1;
                }
                match &self.src[s..self.pos] {
                    b"True" => Lit::Bool(true),
                    b"False" => Lit::Bool(false),
                    b"None" => Lit::None,
                    _ => {
                        self.pos = s;
                        return self.fail("unknown name");
                    }
                }
            }
            Some(_) => return self.fail("unexpected character"),
        };
        Ok((lit, (start, self.pos)))
    }
}
