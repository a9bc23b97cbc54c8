//! Pieces of a volume rendered apart, as the ranks of a distributed render
//! hold them ([`volray_core::piece`]): each piece is its own small
//! `Volume` (its box and ghost layers), framed and sampled as the whole.
//! The pieces take every sample of the whole frame exactly once, even
//! samples lying exactly on the faces between them, and their partial
//! images, composited front to back, give the whole frame.

mod common;

use common::{blobs, colorful, on_the_reference};
use volray_core::camera::{Camera, Projection};
use volray_core::glam::DVec3;
use volray_core::sampling::grid::GridFrame;
use volray_core::{
    Blend, Classification, ClipPlane, PartialImage, Piece, RenderSettings, Renderer, Volume,
};
use volray_core::{FrameRequest, Render};

fn volume() -> Volume {
    blobs(
        [33, 29, 25],
        DVec3::new(1.0, 1.2, 0.9),
        DVec3::new(-3.0, 2.0, 1.0),
    )
}

/// The piece of `volume` owning voxels `lo..hi`, held with its ghosts.
fn piece_of(volume: &Volume, owned: ([usize; 3], [usize; 3])) -> (Volume, Piece) {
    let whole = GridFrame {
        dims: volume.dims(),
        origin: volume.origin(),
        spacing: volume.spacing(),
    };
    let (lo, hi) = Piece::held(owned, volume.dims());
    let renderer = Renderer::new(volume).unwrap();
    let piece = Piece {
        whole,
        offset: lo,
        owned,
        value_range: renderer.value_range(),
        max_gradient: renderer.max_gradient(),
    };
    (volume.sub_box(lo, hi), piece)
}

/// Three pieces along x, cut at voxels 11 and 20: with the default view
/// (along −x, step 1 through the centre) every sample plane is a voxel
/// plane, so the cuts have samples lying exactly on them.
fn slabs(volume: &Volume) -> Vec<(Volume, Piece)> {
    let [nx, ny, nz] = volume.dims();
    [(0, 11), (11, 20), (20, nx)]
        .into_iter()
        .map(|(a, b)| piece_of(volume, ([a, 0, 0], [b, ny, nz])))
        .collect()
}

fn settings(camera: Camera) -> RenderSettings {
    RenderSettings {
        width: 56,
        height: 48,
        camera,
        transfer_function: colorful(),
        background: [0.2, 0.1, 0.3],
        ..RenderSettings::default()
    }
}

fn cameras() -> Vec<(&'static str, Camera)> {
    vec![
        ("along −x", Camera::default()),
        (
            "oblique",
            Camera {
                azimuth: 35.0,
                elevation: -20.0,
                ..Camera::default()
            },
        ),
        (
            "perspective",
            Camera {
                projection: Projection::Perspective { fov_degrees: 35.0 },
                azimuth: -30.0,
                elevation: 10.0,
                ..Camera::default()
            },
        ),
        (
            // The eye inside the volume, in the middle slab.
            "perspective from inside",
            Camera {
                projection: Projection::Perspective { fov_degrees: 70.0 },
                view_point: Some(DVec3::new(11.5, 17.0, 12.0)),
                look_at: Some(DVec3::new(-3.0, 10.0, 12.0)),
                ..Camera::default()
            },
        ),
    ]
}

/// The samples every ray of the frame takes, in all.
fn nominal(renderer: &Renderer, s: &RenderSettings) -> usize {
    renderer.prepare(s).unwrap().nominal_samples()
}

#[test]
fn the_pieces_take_every_sample_of_the_whole_frame_exactly_once() {
    let volume = volume();
    let whole = Renderer::new(&volume).unwrap();
    let pieces = slabs(&volume);
    for (name, camera) in cameras() {
        for (option, s) in [
            ("plain", settings(camera)),
            (
                "half steps, jittered",
                RenderSettings {
                    step: 0.5,
                    jitter: true,
                    ..settings(camera)
                },
            ),
            (
                "cropped and clipped",
                RenderSettings {
                    crop: Some((DVec3::new(0.0, 4.0, 2.0), DVec3::new(24.0, 30.0, 20.0))),
                    clip_planes: vec![ClipPlane {
                        point: DVec3::new(13.0, 18.0, 12.0),
                        normal: DVec3::new(-1.0, 0.5, 0.3),
                    }],
                    ..settings(camera)
                },
            ),
        ] {
            let total = nominal(&whole, &s);
            let taken: usize = (pieces.iter())
                .map(|(v, piece)| {
                    let s = RenderSettings {
                        piece: Some(piece.clone()),
                        ..s.clone()
                    };
                    nominal(&Renderer::new(v).unwrap(), &s)
                })
                .sum();
            assert!(total > 2000, "{name}, {option}: {total}");
            assert_eq!(taken, total, "{name}, {option}");
        }
    }
}

#[test]
fn one_piece_owning_the_whole_grid_renders_the_whole_frame() {
    let volume = volume();
    let whole = Renderer::new(&volume).unwrap();
    let (v, piece) = piece_of(&volume, ([0; 3], volume.dims()));
    let one = Renderer::new(&v).unwrap();
    for (name, camera) in cameras() {
        let s = settings(camera);
        let frame = whole.render(FrameRequest::new(&s)).unwrap().image();
        let with_piece = RenderSettings {
            piece: Some(piece.clone()),
            ..s
        };
        let as_piece = one.render(FrameRequest::new(&with_piece)).unwrap().image();
        assert!(as_piece == frame, "{name}");
    }
}

#[test]
fn slabs_composited_front_to_back_give_the_whole_frame_on_every_path() {
    let volume = volume();
    let whole = Renderer::new(&volume).unwrap();
    let pieces = slabs(&volume);
    let renderers: Vec<Renderer> = pieces
        .iter()
        .map(|(v, _)| Renderer::new(v).unwrap())
        .collect();
    let variants = [
        ("pre", Blend::Composite, Classification::Pre),
        ("post", Blend::Composite, Classification::Post),
        ("maximum", Blend::Maximum, Classification::Pre),
        ("minimum", Blend::Minimum, Classification::Pre),
        ("average", Blend::Average, Classification::Pre),
    ];
    for (name, camera) in cameras() {
        // The slabs are cut across x: front to back is by x, from the eye's
        // side. Rays of the perspective views all start on one side of
        // each cut, but for the eye inside the middle slab (x = 11.5 is
        // voxel 14.5), whose rays go both ways and composite by x alone
        // only for the rays that stay in one direction: it is left to the
        // k-d compositor's tests.
        if name == "perspective from inside" {
            continue;
        }
        for (variant, blend, classification) in variants {
            for reference in [false, true] {
                let s = RenderSettings {
                    blend,
                    classification,
                    ..settings(camera)
                };
                let s = if reference { on_the_reference(&s) } else { s };
                let frame = whole.render(FrameRequest::new(&s)).unwrap().image();
                let mut parts: Vec<PartialImage> = (pieces.iter().zip(&renderers))
                    .map(|((_, piece), r)| {
                        let s = RenderSettings {
                            piece: Some(piece.clone()),
                            ..s.clone()
                        };
                        r.render(FrameRequest::new(&s).partial()).unwrap().partial()
                    })
                    .collect();
                // The eye is on the +x side of every one of these views.
                let mut front = parts.pop().unwrap();
                while let Some(behind) = parts.pop() {
                    front.combine(&behind);
                }
                let piece_settings = RenderSettings {
                    piece: Some(pieces[0].1.clone()),
                    ..s.clone()
                };
                let combined = renderers[0].finish(&piece_settings, front);
                let diff = combined.max_abs_diff(&frame).unwrap();
                // Early termination within each piece drops under 1/1024
                // of each ray's light beyond it (see partial.rs's halves).
                let bound = if reference { 1e-5 } else { 2.0 / 1024.0 };
                assert!(
                    diff <= bound,
                    "{name}, {variant}, reference {reference}: {diff}"
                );
                assert!(frame.pixels().iter().any(|p| p[3] > 0.5), "{name}: empty");
            }
        }
    }
}
