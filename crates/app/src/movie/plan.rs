//! A movie's frames: frame `k` shows the time `k / fps` (in seconds) of
//! the keyframes' timeline, from 0 to the last keyframe's `t` inclusive;
//! the options there ([`Movie::at`]: the keyframes either side, the
//! segment's ease, [`between`]); the data's time point it shows
//! ([`Movie::data_frame`]: held or blended, as the file's `time` says);
//! and a part of the frames (`--movie-frames A:B`, [`part`]).

use super::interpolate::{State, between};
use super::schema::{Keyframe, Keyframes, TimeMode};

/// The data a frame shows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DataFrame {
    /// One time point (`--frame`); `None`: the input as given.
    At(Option<usize>),
    /// `(1 − w)·time point i + w·time point i + 1`, `0 < w < 1`.
    Between(usize, f64),
}

/// The most frames a movie may have: a lying `t` is refused before any
/// work rather than planned.
pub const MAX_FRAMES: usize = 1_000_000;

/// A movie planned from its keyframes.
#[derive(Debug, Clone, PartialEq)]
pub struct Movie {
    pub fps: f64,
    pub time: TimeMode,
    keyframes: Vec<Keyframe>,
}

/// Times within this of a frame's are the frame's (the frame times
/// `k / fps` are not exact in binary).
const EPS: f64 = 1e-9;

impl Movie {
    /// The movie of `keys` at `fps` (the file's, else the command
    /// line's), or why not.
    pub fn new(keys: Keyframes, fps: f64) -> Result<Self, String> {
        let fps = keys.fps.unwrap_or(fps);
        let movie = Movie {
            fps,
            time: keys.time,
            keyframes: keys.keyframes,
        };
        let last = movie.keyframes.last().map_or(0.0, |k| k.t);
        if last * fps + 1.0 > MAX_FRAMES as f64 {
            return Err(format!(
                "the last keyframe's t = {last} s at {fps} frames a second makes more than {MAX_FRAMES} frames"
            ));
        }
        Ok(movie)
    }

    /// The number of frames: time 0 to the last keyframe's, inclusive.
    pub fn frames(&self) -> usize {
        let last = self.keyframes.last().map_or(0.0, |k| k.t);
        (last * self.fps + EPS).floor() as usize + 1
    }

    /// The time frame `k` shows, in seconds.
    pub fn time_of(&self, k: usize) -> f64 {
        k as f64 / self.fps
    }

    /// The keyframes.
    pub fn keyframes(&self) -> &[Keyframe] {
        &self.keyframes
    }

    /// Every option at frame `k`: a keyframe's own where the frame falls
    /// on it (or before the first, after the last), else between the
    /// keyframes either side at the segment's eased fraction. `centre`
    /// is the point looked at by default (the volume's centre).
    pub fn at(&self, k: usize, centre: [f64; 3]) -> State {
        let t = self.time_of(k);
        let keys = &self.keyframes;
        let next = keys.partition_point(|key| key.t <= t + EPS);
        if next == 0 {
            return keys[0].state.clone();
        }
        if next == keys.len() {
            return keys[next - 1].state.clone();
        }
        let (a, b) = (&keys[next - 1], &keys[next]);
        if (t - a.t).abs() <= EPS {
            return a.state.clone();
        }
        let s = a.ease.apply((t - a.t) / (b.t - a.t));
        between(&a.state, &b.state, s, centre)
    }

    /// The data's time point a state shows, as the file's `time` says.
    pub fn data_frame(&self, state: &State) -> DataFrame {
        data_frame(self.time, state.frame)
    }
}

/// The data's time point of a fractional `frame`, held or between two.
pub fn data_frame(time: TimeMode, frame: Option<f64>) -> DataFrame {
    let Some(f) = frame else {
        return DataFrame::At(None);
    };
    let i = (f + EPS).floor();
    let w = f - i;
    match time {
        TimeMode::Interpolate if w > EPS => DataFrame::Between(i as usize, w),
        _ => DataFrame::At(Some(i as usize)),
    }
}

/// The frames `A:B` of `count` names (`B` exclusive; `None`: to the end),
/// checked.
pub fn part(
    start: usize,
    end: Option<usize>,
    count: usize,
) -> Result<std::ops::Range<usize>, String> {
    let end = end.unwrap_or(count);
    if start >= end || end > count {
        return Err(format!(
            "{start}:{end}: the movie has {count} frames, numbered from 0; give A:B with A < B ≤ {count}"
        ));
    }
    Ok(start..end)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::movie::schema::parse;
    use std::path::Path;

    fn movie(text: &str) -> Movie {
        let keys = parse("k.json", text, &State::default(), Path::new(".")).unwrap();
        Movie::new(keys, 24.0).unwrap()
    }

    #[test]
    fn frame_k_shows_time_k_over_fps_to_the_last_keyframe_inclusive() {
        let m = movie(
            r#"{"fps": 4, "keyframes": [
            {"t": 0, "azimuth": 0, "ease": "linear"}, {"t": 2, "azimuth": 80}]}"#,
        );
        assert_eq!(m.frames(), 9);
        // Frame 4 is t = 1 s, half way: 40°; frame 1 a quarter of a second.
        assert_eq!(m.at(4, [0.0; 3]).options.camera.azimuth, 40.0);
        assert_eq!(m.at(1, [0.0; 3]).options.camera.azimuth, 10.0);
        assert_eq!(m.at(8, [0.0; 3]).options.camera.azimuth, 80.0);
        // The command line's fps where the file gives none.
        let n = movie(r#"{"keyframes": [{"t": 0}, {"t": 1}]}"#);
        assert_eq!((n.fps, n.frames()), (24.0, 25));
    }

    #[test]
    fn smooth_segments_ease_and_unchanged_keys_hold() {
        let m = movie(
            r#"{"fps": 4, "keyframes": [
            {"t": 0, "zoom": 1, "elevation": 10},
            {"t": 1, "zoom": 3},
            {"t": 2, "elevation": 50, "ease": "linear"},
            {"t": 3, "zoom": 1}]}"#,
        );
        // Smooth: a quarter of the way in time is 5/32 of the way in value.
        assert_eq!(
            m.at(1, [0.0; 3]).options.camera.zoom,
            1.0 + 2.0 * 5.0 / 32.0
        );
        assert_eq!(m.at(2, [0.0; 3]).options.camera.zoom, 2.0);
        // Elevation not given at t = 1 holds 10 there, then eases to 50.
        assert_eq!(m.at(4, [0.0; 3]).options.camera.elevation, 10.0);
        assert_eq!(m.at(6, [0.0; 3]).options.camera.elevation, 30.0);
        // Zoom held at 3 from t = 1 to 2; the last segment is linear.
        assert_eq!(m.at(6, [0.0; 3]).options.camera.zoom, 3.0);
        assert_eq!(m.at(10, [0.0; 3]).options.camera.zoom, 2.0);
    }

    #[test]
    fn a_fractional_frame_is_held_or_blended() {
        let keys = r#""keyframes": [{"t": 0, "frame": 0, "ease": "linear"}, {"t": 1, "frame": 3}]"#;
        let held = movie(&format!(r#"{{"fps": 4, {keys}}}"#));
        let blended = movie(&format!(r#"{{"fps": 4, "time": "interpolate", {keys}}}"#));
        // Frame 1: t = 0.25 s, frame 0.75; frame 2: 1.5.
        let f = |m: &Movie, k| m.data_frame(&m.at(k, [0.0; 3]));
        assert_eq!(f(&held, 1), DataFrame::At(Some(0)));
        assert_eq!(f(&held, 2), DataFrame::At(Some(1)));
        assert_eq!(f(&blended, 1), DataFrame::Between(0, 0.75));
        assert_eq!(f(&blended, 2), DataFrame::Between(1, 0.5));
        assert_eq!(f(&blended, 4), DataFrame::At(Some(3)));
        assert_eq!(data_frame(TimeMode::Interpolate, None), DataFrame::At(None));
    }

    #[test]
    fn parts_are_checked_against_the_frames() {
        assert_eq!(part(2, Some(5), 10), Ok(2..5));
        assert_eq!(part(2, None, 10), Ok(2..10));
        assert!(part(5, Some(5), 10).is_err());
        assert!(part(0, Some(11), 10).unwrap_err().contains("10 frames"));
        let long = parse(
            "k.json",
            r#"{"keyframes": [{"t": 0}, {"t": 1e12}]}"#,
            &State::default(),
            Path::new("."),
        )
        .unwrap();
        assert!(Movie::new(long, 24.0).is_err());
    }
}
