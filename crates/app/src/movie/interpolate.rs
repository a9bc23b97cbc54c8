//! The values between two keyframes: each option of a frame a fraction
//! `s` (eased, [`Ease`]) of the way from one keyframe's [`State`] to the
//! next's.
//!
//! - Numbers (`azimuth`, `elevation`, `zoom`, `perspective`, `step`,
//!   `shininess`, `iso`, ...) and ranges (`range`, `opacity`, `crop`,
//!   `clip` planes' points and normals, `gradient_opacity`) linearly in
//!   value: an orbit is its angles and its zoom, interpolated.
//! - Directions (`up`, `light`) and the eye (`view`, about the point
//!   looked at) by quaternion: the rotation from one to the other, slerped
//!   (Shoemake, "Animating rotation with quaternion curves", SIGGRAPH
//!   1985), the eye's distance linearly.
//! - Colours (`background`, `light_color`) in OKLab ([`crate::movie::color`]).
//! - Transfer functions (`tf`, `preset`, `colormap`) that differ: each
//!   function built as the flags would build it, then their opacities
//!   (linearly) and colours (in OKLab) mixed at the union of their
//!   control points; a pair that cannot be mixed (the paper's ramp
//!   against a function's opacity, the automatic function) switches at
//!   the later keyframe.
//! - Everything else (`blend`, `shading`, `title`, a `view` against the
//!   framed default, clip planes of different counts) holds the earlier
//!   keyframe's value until the later keyframe's time.
//!
//! Every value is exactly the earlier keyframe's at `s = 0` and the
//! later's at `s = 1`, so a frame at a keyframe's time is the render its
//! flags give.

use super::color;
use volray_core::TransferFunction;
use volray_core::glam::{DQuat, DVec3};
use volray_core::transfer::function::PiecewiseLinear;
use volray_options::{Options, Tf};

/// What a keyframe fixes: every render option (the command line's where
/// no keyframe gave one yet), the data's time point (`frame`, fractional)
/// and the figure's words.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct State {
    pub options: Options,
    /// The data's time point (`--frame`); `None`: the input's first.
    pub frame: Option<f64>,
    /// `--title`, `--label`.
    pub title: Option<String>,
    pub label: Option<String>,
}

/// How a segment between two keyframes runs: at constant speed, or
/// easing in and out (`smooth`, the default: smoothstep, `3s² − 2s³`,
/// whose speed is zero at both keyframes, so a camera path comes to rest
/// at each and starts again without a jerk).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Ease {
    Linear,
    #[default]
    Smooth,
}

impl Ease {
    /// The names the keyframes file takes.
    pub const NAMES: [&'static str; 2] = ["linear", "smooth"];

    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "linear" => Some(Ease::Linear),
            "smooth" => Some(Ease::Smooth),
            _ => None,
        }
    }

    /// The eased fraction of a segment run at the fraction `s` of its time.
    pub fn apply(self, s: f64) -> f64 {
        let s = s.clamp(0.0, 1.0);
        match self {
            Ease::Linear => s,
            Ease::Smooth => s * s * (3.0 - 2.0 * s),
        }
    }
}

/// `a` to `b` at `s`: `a` at 0, `b` at 1 exactly.
pub fn lerp(a: f64, b: f64, s: f64) -> f64 {
    if a == b || s <= 0.0 {
        a
    } else if s >= 1.0 {
        b
    } else {
        a + (b - a) * s
    }
}

fn lerp32(a: f32, b: f32, s: f64) -> f32 {
    if a == b || s <= 0.0 {
        a
    } else if s >= 1.0 {
        b
    } else {
        (f64::from(a) + (f64::from(b) - f64::from(a)) * s) as f32
    }
}

fn lerp3(a: [f64; 3], b: [f64; 3], s: f64) -> [f64; 3] {
    [0, 1, 2].map(|i| lerp(a[i], b[i], s))
}

fn lerp3f(a: [f32; 3], b: [f32; 3], s: f64) -> [f32; 3] {
    [0, 1, 2].map(|i| lerp32(a[i], b[i], s))
}

/// The held value: `a` until the later keyframe.
fn hold<T: Clone>(a: &T, b: &T, s: f64) -> T {
    if s >= 1.0 { b.clone() } else { a.clone() }
}

/// Both given: mixed by `f`; else held.
fn both<T: Clone>(a: &Option<T>, b: &Option<T>, s: f64, f: impl Fn(&T, &T) -> T) -> Option<T> {
    match (a, b) {
        (Some(x), Some(y)) => Some(f(x, y)),
        _ => hold(a, b, s),
    }
}

/// The direction `s` of the way from `a` to `b` by the shortest rotation
/// (a quaternion slerped from the identity), its length mixed linearly.
/// Opposite directions turn about any axis perpendicular to them (glam's
/// choice); a zero vector is held.
pub fn slerp(a: [f64; 3], b: [f64; 3], s: f64) -> [f64; 3] {
    let (va, vb) = (DVec3::from(a), DVec3::from(b));
    if a == b || s <= 0.0 {
        return a;
    }
    if s >= 1.0 {
        return b;
    }
    let (la, lb) = (va.length(), vb.length());
    if la == 0.0 || lb == 0.0 {
        return hold(&a, &b, s);
    }
    let turn = DQuat::from_rotation_arc(va / la, vb / lb);
    let q = DQuat::IDENTITY.slerp(turn, s);
    (q * (va / la) * lerp(la, lb, s)).to_array()
}

/// The eye `s` of the way from `a` to `b`, each about its centre (the
/// point looked at): its direction by [`slerp`], its distance linearly,
/// about the centre mixed linearly.
pub fn orbit_eye(a: [f64; 3], ca: [f64; 3], b: [f64; 3], cb: [f64; 3], s: f64) -> [f64; 3] {
    if s <= 0.0 {
        return a;
    }
    if s >= 1.0 {
        return b;
    }
    let c = DVec3::from(lerp3(ca, cb, s));
    let da = (DVec3::from(a) - DVec3::from(ca)).to_array();
    let db = (DVec3::from(b) - DVec3::from(cb)).to_array();
    (c + DVec3::from(slerp(da, db, s))).to_array()
}

/// The state `s` (eased already) of the way from `a` to `b`; `centre`
/// is the point looked at where no `look_at` is given (the volume's
/// centre), about which the eye turns.
pub fn between(a: &State, b: &State, s: f64, centre: [f64; 3]) -> State {
    let (ca, cb) = (&a.options.camera, &b.options.camera);
    let (la, lb) = (&a.options.look, &b.options.look);
    let mut out = hold(a, b, s);
    let cam = &mut out.options.camera;
    cam.size = ca.size;
    cam.zoom = lerp(ca.zoom, cb.zoom, s);
    cam.azimuth = lerp(ca.azimuth, cb.azimuth, s);
    cam.elevation = lerp(ca.elevation, cb.elevation, s);
    cam.look_at = both(&ca.look_at, &cb.look_at, s, |x, y| lerp3(*x, *y, s));
    cam.view = match (ca.view, cb.view) {
        (Some(x), Some(y)) => Some(orbit_eye(
            x,
            ca.look_at.unwrap_or(centre),
            y,
            cb.look_at.unwrap_or(centre),
            s,
        )),
        _ => hold(&ca.view, &cb.view, s),
    };
    cam.up = slerp(ca.up, cb.up, s);
    cam.perspective = both(&ca.perspective, &cb.perspective, s, |x, y| lerp(*x, *y, s));
    cam.clip = if ca.clip.len() == cb.clip.len() {
        (ca.clip.iter().zip(&cb.clip))
            .map(|((p, n), (q, m))| (lerp3(*p, *q, s), lerp3(*n, *m, s)))
            .collect()
    } else {
        hold(&ca.clip, &cb.clip, s)
    };
    cam.crop = both(&ca.crop, &cb.crop, s, |x, y| {
        (lerp3(x.0, y.0, s), lerp3(x.1, y.1, s))
    });

    let look = &mut out.options.look;
    let pair = |x: &(f32, f32), y: &(f32, f32)| (lerp32(x.0, y.0, s), lerp32(x.1, y.1, s));
    look.opacity = both(&la.opacity, &lb.opacity, s, pair);
    look.gradient_opacity = both(&la.gradient_opacity, &lb.gradient_opacity, s, pair);
    look.range = both(&la.range, &lb.range, s, |x, y| {
        (lerp(x.0, y.0, s), lerp(x.1, y.1, s))
    });
    look.ambient = lerp3f(la.ambient, lb.ambient, s);
    look.diffuse = lerp3f(la.diffuse, lb.diffuse, s);
    look.specular = lerp3f(la.specular, lb.specular, s);
    look.shininess = lerp32(la.shininess, lb.shininess, s);
    look.light = both(&la.light, &lb.light, s, |x, y| slerp(*x, *y, s));
    look.light_color = color::mix(la.light_color, lb.light_color, s);
    look.background = color::mix(la.background, lb.background, s);
    look.iso = both(&la.iso, &lb.iso, s, |x, y| lerp32(*x, *y, s));
    look.iso_thickness = both(&la.iso_thickness, &lb.iso_thickness, s, |x, y| {
        lerp32(*x, *y, s)
    });
    look.ambient_occlusion = both(&la.ambient_occlusion, &lb.ambient_occlusion, s, |x, y| {
        lerp(*x, *y, s)
    });
    if (&la.tf, &la.preset, &la.colormap) != (&lb.tf, &lb.preset, &lb.colormap)
        && s > 0.0
        && s < 1.0
        && let Some(f) = mixed_function(a, b, s)
    {
        look.tf = Some(Tf::Function(f));
        look.preset = None;
        look.colormap = None;
        // The mixed function holds the windows; the ramp is its opacity.
        look.range = None;
        look.opacity = None;
    }
    let (sa, sb) = (&a.options.sampling, &b.options.sampling);
    out.options.sampling.step = lerp(sa.step, sb.step, s);
    out.frame = both(&a.frame, &b.frame, s, |x, y| lerp(*x, *y, s));
    out
}

/// The transfer function `s` of the way from `a`'s to `b`'s (each as the
/// flags build it, window and all), or `None` where they cannot be mixed.
fn mixed_function(a: &State, b: &State, s: f64) -> Option<TransferFunction> {
    let built = |state: &State| {
        let look = &state.options.look;
        if look.auto_tf() || look.log {
            return None;
        }
        volray_options::named_transfer_function(look).ok()
    };
    let (fa, fb) = (built(a)?, built(b)?);
    let domain = match (fa.domain, fb.domain) {
        (Some(x), Some(y)) => Some((lerp(x.0, y.0, s), lerp(x.1, y.1, s))),
        (None, None) => None,
        _ => return None,
    };
    let opacity = match (&fa.opacity, &fb.opacity) {
        (Some(x), Some(y)) => Some(mix_points(x, y, |p, q| [lerp32(p[0], q[0], s)])?),
        (None, None) => None,
        _ => return None,
    };
    let color = match (&fa.color, &fb.color) {
        (Some(x), Some(y)) => Some(mix_points(x, y, |p, q| color::mix(*p, *q, s))?),
        (None, None) => None,
        (Some(x), None) => Some(mix_points(x, &white(), |p, q| color::mix(*p, *q, s))?),
        (None, Some(y)) => Some(mix_points(&white(), y, |p, q| color::mix(*p, *q, s))?),
    };
    Some(TransferFunction {
        domain,
        opacity,
        color,
    })
}

/// A transfer function's default colour (none given: white).
fn white() -> PiecewiseLinear<3> {
    PiecewiseLinear::constant([1.0; 3])
}

/// Two piecewise-linear functions mixed by `f` at the union of their
/// control points (each evaluated there): the mix of two
/// piecewise-linear functions at one `s` is piecewise linear between
/// those points only if `f` is linear; for colours in OKLab it is close,
/// and exact at the points.
fn mix_points<const N: usize>(
    a: &PiecewiseLinear<N>,
    b: &PiecewiseLinear<N>,
    f: impl Fn(&[f32; N], &[f32; N]) -> [f32; N],
) -> Option<PiecewiseLinear<N>> {
    let mut ts: Vec<f32> = (a.points().iter().chain(b.points())).map(|p| p.0).collect();
    ts.sort_by(f32::total_cmp);
    ts.dedup();
    let points = ts
        .into_iter()
        .map(|t| (t, f(&a.eval(t), &b.eval(t))))
        .collect();
    PiecewiseLinear::new("mixed", points).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn eases_at_the_middle_and_a_quarter_of_a_segment() {
        assert_eq!(Ease::Linear.apply(0.5), 0.5);
        assert_eq!(Ease::Smooth.apply(0.5), 0.5);
        assert_eq!(Ease::Linear.apply(0.25), 0.25);
        // 3·(1/4)² − 2·(1/4)³ = 3/16 − 1/32 = 5/32.
        assert_eq!(Ease::Smooth.apply(0.25), 5.0 / 32.0);
        assert_eq!(Ease::Smooth.apply(0.0), 0.0);
        assert_eq!(Ease::Smooth.apply(1.0), 1.0);
    }

    #[test]
    fn numbers_move_linearly_and_hit_their_keyframes_exactly() {
        assert_eq!(lerp(0.1, 0.7, 1.0), 0.7);
        assert_eq!(lerp(0.1, 0.7, 0.0), 0.1);
        assert!(close(lerp(10.0, 30.0, 0.25), 15.0));
        let mut a = State::default();
        let mut b = State::default();
        a.options.camera.azimuth = 0.0;
        b.options.camera.azimuth = 90.0;
        b.options.camera.zoom = 3.0;
        a.options.look.range = Some((0.0, 100.0));
        b.options.look.range = Some((50.0, 200.0));
        let mid = between(&a, &b, 0.5, [0.0; 3]);
        assert_eq!(mid.options.camera.azimuth, 45.0);
        assert_eq!(mid.options.camera.zoom, 2.0);
        assert_eq!(mid.options.look.range, Some((25.0, 150.0)));
        assert_eq!(between(&a, &b, 1.0, [0.0; 3]), b);
        assert_eq!(between(&a, &b, 0.0, [0.0; 3]).options, a.options);
    }

    #[test]
    fn a_view_turns_about_the_centre_by_the_quaternion_between_its_ends() {
        // From +x to +y about the origin, half way is the diagonal at the
        // same distance: (cos 45°, sin 45°, 0)·2.
        let mid = slerp([2.0, 0.0, 0.0], [0.0, 2.0, 0.0], 0.5);
        let h = 2.0 * std::f64::consts::FRAC_1_SQRT_2;
        assert!(
            close(mid[0], h) && close(mid[1], h) && close(mid[2], 0.0),
            "{mid:?}"
        );
        // A third of the way turns 30°.
        let third = slerp([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 1.0 / 3.0);
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        assert!(close(third[0], c) && close(third[1], s), "{third:?}");
        // About a centre at (1, 1, 1), the eye 2 away along x, then y.
        let mut a = State::default();
        let mut b = State::default();
        a.options.camera.view = Some([3.0, 1.0, 1.0]);
        b.options.camera.view = Some([1.0, 3.0, 1.0]);
        let eye = between(&a, &b, 0.5, [1.0; 3]).options.camera.view.unwrap();
        assert!(close(eye[0], 1.0 + h) && close(eye[1], 1.0 + h) && close(eye[2], 1.0));
        // A view against the framed default is held until the keyframe.
        b.options.camera.view = None;
        assert_eq!(
            between(&a, &b, 0.9, [1.0; 3]).options.camera.view,
            Some([3.0, 1.0, 1.0])
        );
        assert_eq!(between(&a, &b, 1.0, [1.0; 3]).options.camera.view, None);
    }

    #[test]
    fn discrete_options_hold_and_colours_mix_in_oklab() {
        let mut a = State::default();
        let mut b = State::default();
        a.title = Some("before".into());
        b.title = Some("after".into());
        a.options.look.shading = true;
        b.options.look.shading = false;
        b.options.look.background = [1.0, 1.0, 1.0];
        let mid = between(&a, &b, 0.5, [0.0; 3]);
        assert_eq!(mid.title.as_deref(), Some("before"));
        assert!(mid.options.look.shading);
        assert_eq!(
            mid.options.look.background,
            color::mix(a.options.look.background, [1.0; 3], 0.5)
        );
    }

    #[test]
    fn transfer_functions_fade_point_by_point() {
        let tf = |opacity: f32| TransferFunction {
            domain: None,
            opacity: Some(PiecewiseLinear::new("o", vec![(0.0, [0.0]), (1.0, [opacity])]).unwrap()),
            color: Some(PiecewiseLinear::constant([1.0, 0.5, 0.0])),
        };
        let mut a = State::default();
        let mut b = State::default();
        a.options.look.tf = Some(Tf::Function(tf(0.2)));
        b.options.look.tf = Some(Tf::Function(tf(0.6)));
        let mid = between(&a, &b, 0.25, [0.0; 3]);
        let Some(Tf::Function(f)) = mid.options.look.tf else {
            panic!("not mixed")
        };
        let o = f.opacity.unwrap();
        assert_eq!(o.points()[1].1[0], (0.2f64 + 0.4 * 0.25) as f32);
        assert_eq!(f.color.unwrap().eval(0.5), [1.0, 0.5, 0.0]);
    }
}
