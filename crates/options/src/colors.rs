//! Colours by name, as every front end takes them: the fluorescence
//! palette that channels are coloured from by default (the command line's
//! `--channels`, Python's `channel_axis`), and a few more names.

/// The default colours of channels, in order (then again from the first):
/// the fluorescence palette.
pub const CHANNEL_PALETTE: [(&str, [f32; 3]); 8] = [
    ("magenta", [1.0, 0.0, 1.0]),
    ("green", [0.0, 1.0, 0.0]),
    ("cyan", [0.0, 1.0, 1.0]),
    ("yellow", [1.0, 1.0, 0.0]),
    ("red", [1.0, 0.0, 0.0]),
    ("blue", [0.0, 0.0, 1.0]),
    ("orange", [1.0, 0.5, 0.0]),
    ("white", [1.0, 1.0, 1.0]),
];

/// Colour names taken beside the palette's.
const MORE: [(&str, [f32; 3]); 5] = [
    ("grey", [0.5, 0.5, 0.5]),
    ("gray", [0.5, 0.5, 0.5]),
    ("purple", [0.5, 0.0, 1.0]),
    ("pink", [1.0, 0.4, 0.7]),
    ("black", [0.0, 0.0, 0.0]),
];

/// Channel `i`'s default colour.
pub fn channel_colour(i: usize) -> [f32; 3] {
    CHANNEL_PALETTE[i % CHANNEL_PALETTE.len()].1
}

/// The colour `name` names (any case), if any.
pub fn named(name: &str) -> Option<[f32; 3]> {
    let lower = name.trim().to_ascii_lowercase();
    (CHANNEL_PALETTE.iter().chain(&MORE))
        .find(|(n, _)| *n == lower)
        .map(|&(_, rgb)| rgb)
}

/// The names [`named`] takes, for messages (`gray` left out beside `grey`).
pub fn names() -> Vec<&'static str> {
    (CHANNEL_PALETTE.iter().chain(&MORE))
        .map(|(n, _)| *n)
        .filter(|n| *n != "gray")
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_find_their_colours_in_any_case() {
        assert_eq!(named("Magenta"), Some([1.0, 0.0, 1.0]));
        assert_eq!(named(" gray "), named("grey"));
        assert_eq!(named("teal"), None);
        assert_eq!(channel_colour(9), [0.0, 1.0, 0.0]);
        assert!(names().contains(&"pink") && !names().contains(&"gray"));
    }
}
