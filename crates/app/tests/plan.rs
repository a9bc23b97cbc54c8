//! Opening and planning inputs: a chunked pyramid's level chosen for the
//! picture and read whole or in pieces as the memory bound predicts, a
//! raw file read as its layout says, and the options refused with the
//! input they were given for.

use volray_app::AppError;
use volray_app::input::{self, Request, Spec};
use volray_app::memory::png_bytes;
use volray_app::plan::{self, Chosen, Frames, Plan};
use volray_core::{MemoryBound, NonFinite, RenderSettings, SampleType, Volume};
use volray_io::{OmeZarrOptions, write_ome_zarr};
use volray_options::level::LevelChoice;

/// A 64³ ramp written as an OME-Zarr pyramid of 16³ chunks: levels 64³,
/// 32³ and 16³, voxels 1, 2 and 4 units apart.
fn pyramid(dir: &tempfile::TempDir) -> std::path::PathBuf {
    let path = dir.path().join("ramp.ome.zarr");
    let values: Vec<f32> = (0..64 * 64 * 64).map(|i| (i % 64) as f32).collect();
    let volume = Volume::new([64; 3], values).unwrap();
    let options = OmeZarrOptions {
        chunk: 16,
        shard: 32,
        ..OmeZarrOptions::default()
    };
    write_ome_zarr(&path, &volume, &options).unwrap();
    path
}

fn frames(settings: &RenderSettings) -> Frames<'_> {
    Frames {
        settings,
        non_finite: NonFinite::Refuse,
        log: false,
        labels: false,
        extra: png_bytes(settings),
    }
}

/// What a frame of `settings` of an `f32` cube of `side` points takes
/// whole: volray-core's bound and the 16-bit PNG's 8 bytes a pixel.
fn whole_bytes(side: usize, spacing: f64, settings: &RenderSettings) -> u128 {
    let bound = MemoryBound::new(
        [side; 3],
        volray_core::glam::DVec3::splat(spacing),
        SampleType::F32,
        settings,
        NonFinite::Refuse,
        0,
    );
    bound.total() + 8 * (settings.width * settings.height) as u128
}

#[test]
fn level_auto_takes_the_coarsest_level_a_pixel_resolves_and_reads_it_whole_when_it_fits() {
    let dir = tempfile::tempdir().unwrap();
    let request = Request {
        level: Some(LevelChoice::Auto),
        max_memory: Some(1 << 30),
        ..Request::of(pyramid(&dir).to_str().unwrap())
    };
    // A 32² picture of the 64-unit box: a pixel spans 2 units, the
    // voxels of level 1.
    let settings = RenderSettings {
        width: 32,
        height: 32,
        ..RenderSettings::default()
    };
    let mut said = Vec::new();
    let plan = plan::plan(&request, &frames(&settings), &mut |c| said.push(c)).unwrap();
    assert!(matches!(plan, Plan::Whole { level: Some(1) }));
    let chosen = Chosen {
        level: 1,
        levels: 3,
        dims: [32; 3],
    };
    assert_eq!(said, [chosen]);
    // Read whole at that level: the 32³ grid.
    let input = input::load(&request.at_level(Some(1))).unwrap();
    assert_eq!(input.volume.dims(), [32; 3]);
}

#[test]
fn a_level_whose_frame_is_over_the_limit_is_rendered_in_pieces() {
    let dir = tempfile::tempdir().unwrap();
    let path = pyramid(&dir);
    let settings = RenderSettings {
        width: 64,
        height: 64,
        ..RenderSettings::default()
    };
    let need = whole_bytes(64, 1.0, &settings);
    let at = |max_memory: u128| Request {
        level: Some(LevelChoice::Index(0)),
        max_memory: Some(u64::try_from(max_memory).unwrap()),
        ..Request::of(path.to_str().unwrap())
    };
    // Exactly what the frame takes: whole.
    let plan = plan::plan(&at(need), &frames(&settings), &mut |_| {}).unwrap();
    assert!(matches!(plan, Plan::Whole { level: Some(0) }));
    // A byte less: in pieces, saying what it would take whole.
    let plan = plan::plan(&at(need - 1), &frames(&settings), &mut |_| {}).unwrap();
    let Plan::Streamed(mut streamed) = plan else {
        panic!("not in pieces")
    };
    assert_eq!((streamed.level, streamed.whole), (0, need));
    assert_eq!(streamed.max_memory as u128, need - 1);
    assert!(!streamed.over_piece_budget());
    // Its frame, less the PNG the pieces do not hold, fits in one piece.
    let look = volray_options::LookOptions::default();
    let settings = streamed.settings_from_volume(&look, settings).unwrap();
    let (image, times) = streamed.render(&settings, &|_| {}).unwrap();
    assert_eq!((image.width(), image.height()), (64, 64));
    assert_eq!(times.pieces, 1);
    // Half of it: the level is split until a piece fits, and every
    // piece is read.
    let plan = plan::plan(&at(need / 2), &frames(&settings), &mut |_| {}).unwrap();
    let Plan::Streamed(mut streamed) = plan else {
        panic!("not in pieces")
    };
    let (_, times) = streamed.render(&settings, &|_| {}).unwrap();
    assert!(times.pieces >= 2, "{} pieces", times.pieces);
    assert_eq!(streamed.streamed.pieces(), times.pieces);
    assert!(times.read_voxels >= 64 * 64 * 64, "{}", times.read_voxels);
}

#[test]
fn built_in_sources_and_files_read_whole_are_planned_whole() {
    let settings = RenderSettings::default();
    let plan = plan::plan(&Request::of("sphere:16"), &frames(&settings), &mut |_| {}).unwrap();
    assert!(matches!(plan, Plan::Whole { level: None }));
    assert_eq!(
        Request::of("sphere:16").spec,
        Spec::Source("sphere:16".into())
    );
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("cube.raw");
    std::fs::write(&raw, [0u8; 27]).unwrap();
    let request = Request {
        dims: Some([3, 3, 3]),
        dtype: Some("u8".into()),
        level: Some(LevelChoice::Auto),
        ..Request::of(raw.to_str().unwrap())
    };
    // level auto on a file of one level is refused, naming it.
    let err = plan::plan(&request, &frames(&settings), &mut |_| {}).err();
    let Some(AppError::AutoLevelOneLevel { spec }) = err else {
        panic!("{err:?}")
    };
    assert_eq!(spec, raw.display().to_string());
}

#[test]
fn a_raw_file_is_read_as_its_layout_says() {
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("ramp.raw");
    // 4 x 3 x 2 big-endian u16: value i at index i.
    let bytes: Vec<u8> = (0..24u16).flat_map(u16::to_be_bytes).collect();
    std::fs::write(&raw, bytes).unwrap();
    let request = Request {
        dims: Some([4, 3, 2]),
        dtype: Some("u16".into()),
        endian: Some("big".into()),
        spacing: Some([1.0, 2.0, 3.0]),
        ..Request::of(raw.to_str().unwrap())
    };
    let input = input::load(&request).unwrap();
    let v = &input.volume;
    assert_eq!(v.dims(), [4, 3, 2]);
    assert_eq!(v.spacing().to_array(), [1.0, 2.0, 3.0]);
    assert_eq!(v.sample_type(), SampleType::U16);
    // x fastest: (x, y, z) holds x + 4 y + 12 z.
    assert_eq!(v.get(3, 2, 1), 23.0);
    assert_eq!(v.get(1, 1, 0), 5.0);
    // --log: log10 of each value, the zero taking the smallest positive's.
    let logged = input::load_log(&request, true).unwrap();
    assert_eq!(logged.volume.get(3, 2, 1), 23f64.log10() as f32);
    assert_eq!(logged.volume.get(0, 0, 0), 0.0);
}

#[test]
fn options_that_do_not_apply_are_refused_naming_the_input() {
    let sphere = Request {
        frame: Some(1),
        ..Request::of("sphere:16")
    };
    let Err(AppError::FileOptionsOnSource { spec }) = input::load(&sphere) else {
        panic!("a frame of a built-in source")
    };
    assert_eq!(spec, "sphere:16");
    let npy = Request {
        dtype: Some("u8".into()),
        ..Request::of("volume.npy")
    };
    let Err(AppError::RawLayoutOnFormat { spec, format }) = input::load(&npy) else {
        panic!("a raw layout for a .npy file")
    };
    assert_eq!((spec.as_str(), format), ("volume.npy", "NumPy .npy"));
    let raw = Request {
        dtype: Some("u8".into()),
        ..Request::of("volume.raw")
    };
    let Err(AppError::RawNeedsDims { path }) = input::load(&raw) else {
        panic!("a raw file without dims")
    };
    assert_eq!(path, "volume.raw");
}
