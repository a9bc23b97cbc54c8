//! Distributed frames with ranks as threads (the MPI runs are the CLI's
//! tests): for 1 to 8 ranks, the frame composited on rank 0 is the frame
//! one process renders, within 1/255 per channel, orthographic and
//! perspective (the eye outside and inside the volume), with shading,
//! crop and clip planes, every blend mode and post-classification; and
//! the same from run to run.

use volray_core::camera::Camera;
use volray_core::glam::DVec3;
use volray_core::{FrameRequest, Image, Render, RenderSettings, Renderer, Volume};
use volray_distributed::frame::{Distributed, FrameError};
use volray_distributed::transport::Local;

mod common;
use common::{cases, volume};

/// The frame of `settings` rendered by `ranks` threads, on rank 0.
fn distributed(volume: &Volume, settings: &RenderSettings, ranks: usize) -> Image {
    let mut frames: Vec<Option<Image>> = std::thread::scope(|s| {
        let handles: Vec<_> = (Local::group(ranks).into_iter())
            .map(|t| {
                s.spawn(move || {
                    let mut d = Distributed::read(&t, volume, Default::default()).unwrap();
                    d.render(settings).unwrap().0
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert!(frames[1..].iter().all(Option::is_none));
    frames.swap_remove(0).expect("rank 0's frame")
}

#[test]
fn one_to_eight_ranks_give_the_single_process_frame_within_a_level() {
    let volume = volume();
    let renderer = Renderer::new(&volume).unwrap();
    let mut worst: f32 = 0.0;
    for (name, settings) in cases() {
        let single = renderer
            .render(FrameRequest::new(&settings))
            .unwrap()
            .image();
        assert!(
            single.pixels().iter().any(|p| p[3] > 0.3),
            "{name}: nearly empty"
        );
        for ranks in 1..=8 {
            let frame = distributed(&volume, &settings, ranks);
            let diff = frame.max_abs_diff(&single).unwrap();
            worst = worst.max(diff);
            assert!(diff <= 1.0 / 255.0, "{name}, {ranks} ranks: {diff}");
        }
    }
    println!("largest difference from one process: {worst:e}");
}

#[test]
fn the_same_rank_count_gives_the_same_frame_bit_for_bit() {
    let volume = volume();
    for (name, settings) in cases().into_iter().step_by(3) {
        let a = distributed(&volume, &settings, 5);
        let b = distributed(&volume, &settings, 5);
        assert!(a == b, "{name}");
    }
}

/// A source whose read fails on one box.
/// A source whose boxes past x = 0 fail with an error of its kind.
struct Failing(Volume, volray_core::SourceErrorKind);

impl volray_distributed::frame::Source for Failing {
    fn grid(&self) -> volray_core::sampling::grid::GridFrame {
        volray_distributed::frame::Source::grid(&self.0)
    }
    fn sample_type(&self) -> volray_core::SampleType {
        self.0.sample_type()
    }
    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Volume, volray_core::SourceError> {
        if lo[0] > 0 {
            return Err(volray_core::SourceError::new(
                self.1,
                "scan.raw: unexpected end of file at byte 4096",
            ));
        }
        self.0.read_box(lo, hi)
    }
}

#[test]
fn a_rank_that_cannot_read_its_piece_fails_every_rank_with_its_error_and_its_kind() {
    use volray_core::SourceErrorKind::{BadData, Io};
    for (kind, bad_input) in [(BadData, true), (Io, false)] {
        let errors = failures(Failing(volume(), kind));
        for e in &errors {
            assert_eq!(e, &errors[0]);
        }
        let FrameError::Rank {
            rank,
            message,
            bad_input: said,
        } = &errors[0]
        else {
            panic!("{:?}", errors[0])
        };
        assert_eq!(*rank, 2, "the first rank whose box starts past x = 0");
        assert!(message.contains("scan.raw"), "{message}");
        assert_eq!(*said, bad_input, "{kind:?}");
    }
}

/// Every rank's error reading `source` in 4 ranks.
fn failures(source: Failing) -> Vec<FrameError> {
    std::thread::scope(|s| {
        let handles: Vec<_> = (Local::group(4).into_iter())
            .map(|t| {
                let source = &source;
                s.spawn(move || {
                    Distributed::read(&t, source, Default::default())
                        .err()
                        .unwrap()
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    })
}

/// A label volume: every rank's labels, joined, are the whole volume's
/// (each label lies in one rank's piece only, at 3 and 5 ranks), and
/// the frame with their transfer function is one process's within a
/// level; a value that is not an integer is found on whichever rank
/// holds it.
#[test]
fn ranks_join_their_labels_into_the_whole_volumes() {
    use volray_core::transfer::labels::{LabelError, LabelStyle, labels_of, transfer_function};
    // Label 3 in a corner ball, 7 in the opposite corner, 1 across the
    // middle: no rank at 3 or more holds all three.
    let mut volume = Volume::from_fn([30, 26, 22], DVec3::ONE, DVec3::ZERO, |p| {
        if (p - DVec3::new(5.0, 5.0, 4.0)).length() < 4.0 {
            3.0
        } else if (p - DVec3::new(24.0, 20.0, 17.0)).length() < 4.5 {
            7.0
        } else if (p - DVec3::new(15.0, 13.0, 11.0)).length() < 6.0 {
            1.0
        } else {
            0.0
        }
    })
    .unwrap();
    volume.set_labels(true);
    let found = labels_of(&volume, 256).unwrap().unwrap();
    assert_eq!(found, vec![0, 1, 3, 7]);
    let settings = RenderSettings {
        width: 48,
        height: 40,
        transfer_function: transfer_function(&found, &LabelStyle::default()).unwrap(),
        camera: Camera {
            azimuth: 35.0,
            elevation: 20.0,
            ..Camera::default()
        },
        ..RenderSettings::default()
    };
    let single = Renderer::new(&volume).unwrap();
    let single = single.render(FrameRequest::new(&settings)).unwrap().image();
    for ranks in [1, 3, 5] {
        let results: Vec<_> = std::thread::scope(|s| {
            let handles: Vec<_> = (Local::group(ranks).into_iter())
                .map(|t| {
                    let (volume, settings) = (&volume, &settings);
                    s.spawn(move || {
                        let mut d = Distributed::read(&t, volume, Default::default()).unwrap();
                        let joined = d.labels(256).unwrap();
                        (joined, d.render(settings).unwrap().0)
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        for (joined, _) in &results {
            assert_eq!(
                joined.as_ref().unwrap().as_deref(),
                Some(&found[..]),
                "{ranks} ranks"
            );
        }
        let frame = results[0].1.as_ref().expect("rank 0's frame");
        let diff = frame.max_abs_diff(&single).unwrap();
        assert!(diff <= 1.0 / 255.0, "{ranks} ranks: {diff}");
    }
    // A half in the far corner: only the last rank's piece holds it.
    let mut half = volume.values().to_vec();
    let n = half.len();
    half[n - 1] = 0.5;
    let half = Volume::new(volume.dims(), half).unwrap();
    let joined: Vec<_> = std::thread::scope(|s| {
        let handles: Vec<_> = (Local::group(3).into_iter())
            .map(|t| {
                let half = &half;
                s.spawn(move || {
                    let d = Distributed::read(&t, half, Default::default()).unwrap();
                    d.labels(256).unwrap()
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for j in joined {
        assert!(
            matches!(j, Err(LabelError::NotInteger(v)) if v == 0.5),
            "{j:?}"
        );
    }
}

#[test]
fn two_channels_across_one_to_five_ranks_give_the_single_process_scene_within_a_level() {
    use volray_core::PiecewiseLinear;
    use volray_core::scene::{Look, Mix, Scene, SceneSettings};
    use volray_distributed::scene::DistributedScene;
    // Two channels of one grid: the common blobs, and waves on its grid.
    let a = volume();
    let b = Volume::from_fn(a.dims(), a.spacing(), a.origin(), |p| {
        (0.5 + 0.4 * (p.x * 0.4).sin() * (p.y * 0.3 + p.z * 0.2).cos()) as f32
    })
    .unwrap();
    let single = Scene::new(vec![Renderer::new(&a).unwrap(), Renderer::new(&b).unwrap()]).unwrap();
    for (name, settings) in cases()
        .into_iter()
        .filter(|(_, s)| !s.blend.is_projection())
    {
        let looks = vec![
            Look::of(&settings),
            Look {
                transfer_function: volray_core::TransferFunction {
                    opacity: Some(
                        PiecewiseLinear::new("opacity", vec![(0.6, [0.0]), (1.0, [0.5])]).unwrap(),
                    ),
                    color: Some(PiecewiseLinear::constant([0.0, 1.0, 0.2])),
                    domain: None,
                },
                iso: None,
                gradient_opacity: None,
                ..Look::of(&settings)
            },
        ];
        let request = SceneSettings {
            settings: settings.clone(),
            looks,
            mix: Mix::Composite,
        };
        let want = single.render(FrameRequest::new(&request)).unwrap().image();
        for ranks in [1, 2, 3, 5] {
            let frames: Vec<Option<Image>> = std::thread::scope(|s| {
                let handles: Vec<_> = (Local::group(ranks).into_iter())
                    .map(|t| {
                        let (a, b, request) = (&a, &b, &request);
                        s.spawn(move || {
                            let sources: [&dyn volray_distributed::frame::Source; 2] = [a, b];
                            let mut d =
                                DistributedScene::read(&t, &sources, Default::default()).unwrap();
                            d.render(request).unwrap().0
                        })
                    })
                    .collect();
                handles.into_iter().map(|h| h.join().unwrap()).collect()
            });
            assert!(frames[1..].iter().all(Option::is_none));
            let frame = frames[0].as_ref().expect("rank 0's frame");
            let diff = frame.max_abs_diff(&want).unwrap();
            assert!(diff <= 1.0 / 255.0, "{name}, {ranks} ranks: {diff}");
        }
    }
}
