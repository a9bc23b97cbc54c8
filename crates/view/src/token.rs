//! The access token: 128 random bits from the operating system, written
//! as 32 hexadecimal digits, that every request must carry
//! (`?token=...`). Anyone who can reach the port but was not given the
//! URL (another user of a shared login node, a web page the browser is
//! showing) is refused. The comparison takes the same time whatever the
//! first differing digit, so the token cannot be guessed a digit at a time.

use std::fmt;

/// Bytes of randomness in a token.
const TOKEN_BYTES: usize = 16;

/// A random access token.
#[derive(Clone, PartialEq, Eq)]
pub struct Token(String);

/// The operating system could not supply random bytes.
#[derive(Debug, thiserror::Error)]
#[error("no random bytes from the operating system for the access token: {0}")]
pub struct NoRandomness(String);

impl Token {
    /// A new token of 128 bits from the operating system.
    pub fn generate() -> Result<Token, NoRandomness> {
        let mut bytes = [0u8; TOKEN_BYTES];
        getrandom::fill(&mut bytes).map_err(|e| NoRandomness(e.to_string()))?;
        Ok(Token(bytes.iter().map(|b| format!("{b:02x}")).collect()))
    }

    /// The token as it appears in URLs.
    pub fn as_str(&self) -> &str {
        &self.0
    }

    /// Whether `given` is this token, compared in constant time.
    pub fn matches(&self, given: &str) -> bool {
        let (ours, theirs) = (self.0.as_bytes(), given.as_bytes());
        if ours.len() != theirs.len() {
            return false;
        }
        ours.iter()
            .zip(theirs)
            .fold(0u8, |diff, (a, b)| diff | (a ^ b))
            == 0
    }

    /// Whether the query string of a request (`a=1&token=...`) carries
    /// this token.
    pub fn in_query(&self, query: Option<&str>) -> bool {
        query
            .into_iter()
            .flat_map(|q| q.split('&'))
            .filter_map(|pair| pair.strip_prefix("token="))
            .any(|given| self.matches(given))
    }
}

/// Shows only that it is a token, so that logs and panics do not leak it.
impl fmt::Debug for Token {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("Token(..)")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_are_128_bit_hex_and_differ() {
        let a = Token::generate().unwrap();
        let b = Token::generate().unwrap();
        assert_eq!(a.as_str().len(), 32);
        assert!(a.as_str().bytes().all(|c| c.is_ascii_hexdigit()));
        assert_ne!(a, b);
        assert_eq!(format!("{a:?}"), "Token(..)");
    }

    #[test]
    fn only_the_exact_token_matches() {
        let token = Token::generate().unwrap();
        let text = token.as_str().to_string();
        assert!(token.matches(&text));
        assert!(!token.matches(""));
        assert!(!token.matches(&text[..31]));
        assert!(!token.matches(&format!("{text}0")));
        if text != text.to_uppercase() {
            assert!(!token.matches(&text.to_uppercase()));
        }
        let mut flipped = text.clone().into_bytes();
        flipped[31] = if flipped[31] == b'0' { b'1' } else { b'0' };
        assert!(!token.matches(std::str::from_utf8(&flipped).unwrap()));
    }

    #[test]
    fn the_token_is_read_from_the_query() {
        let token = Token::generate().unwrap();
        let t = token.as_str();
        assert!(token.in_query(Some(&format!("token={t}"))));
        assert!(token.in_query(Some(&format!("a=1&token={t}&b=2"))));
        assert!(!token.in_query(None));
        assert!(!token.in_query(Some("token=")));
        assert!(!token.in_query(Some(&format!("xtoken={t}"))));
        assert!(!token.in_query(Some(&format!("token={t}x"))));
    }
}
