//! Movies of `volray render`: `--keyframes FILE` (volray-app's `movie`:
//! the file read into the flags' options, the values between keyframes,
//! frame `k` at time `k / fps`) and `--turntable N` written as a movie
//! (`.mp4`, `.webm`) or resumably. Each frame is rendered as `volray
//! render` renders a still with the frame's options (a keyframe means
//! what its flags mean), annotated, and handed on at once: to ffmpeg
//! (volray-io's `ffmpeg`, as the frames come) or volray-io's `Animation` (`.gif`,
//! animated `.png`, numbered PNGs). Nothing appears at the output until
//! every frame is in.
//!
//! With `--resume` or `--movie-frames A:B` the frames are kept in a work
//! folder beside the output (volray-app's `movie::work`) as they finish; a run renders
//! only the frames missing there, and the movie is encoded from the
//! folder once every frame is in it (then the folder is deleted).
//!
//! Frames are rendered in runs that show one time point of the data: the
//! time point is read (two, blended, for `"time": "interpolate"`), its
//! renderer built once, and every frame of the run rendered with it. A
//! volume too large to read whole is rendered piece by piece, frame by
//! frame, as its stills are.

use crate::error::CliError;
use crate::outfile::DEFAULT_FPS;
use crate::session::{app_failure, load, renderer_for, streamed_note, thread_pool};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;
use volray_app::animation::turntable_frame;
use volray_app::input::Input;
use volray_app::movie::work::Work;
use volray_app::movie::{DataFrame, Movie, State};
use volray_app::plan::{Plan, StreamedInput};
use volray_core::{FrameRequest, Image, Render, RenderSettings, Rendered, TransferFunction};
use volray_flags::{InputArgs, RenderArgs};
use volray_io::ffmpeg::{self, Codec, Encoder};
use volray_io::{Animation, AnimationKind};
use volray_options::LookOptions;

/// Whether `args` ask for a movie this module renders: keyframes, or a
/// turntable written as `.mp4`/`.webm` or kept frame by frame.
pub fn wanted(args: &RenderArgs) -> bool {
    let a = &args.animation;
    a.keyframes.is_some()
        || (a.turntable.is_some()
            && (Codec::of(&args.out.output).is_some() || a.resume || a.movie_frames.is_some()))
}

/// The flags only a movie takes, refused elsewhere.
pub fn refuse_movie_flags(args: &RenderArgs) -> Result<(), CliError> {
    let a = &args.animation;
    for (given, flag) in [
        (a.crf.is_some(), "--crf"),
        (a.resume, "--resume"),
        (a.movie_frames.is_some(), "--movie-frames"),
    ] {
        if given {
            return Err(CliError::input(format!(
                "{flag} applies to movies: give --keyframes FILE or --turntable FRAMES"
            )));
        }
    }
    if Codec::of(&args.out.output).is_some() {
        return Err(CliError::input(format!(
            "{}: a movie is rendered from --keyframes FILE or --turntable FRAMES",
            args.out.output.display()
        )));
    }
    Ok(())
}

/// What each frame shows: a keyframes file's path, or a turntable's.
enum Path {
    Keys { movie: Movie, file: PathBuf },
    Turntable(usize),
}

/// Where the frames go.
enum Sink {
    Ffmpeg(Encoder),
    Animation(Animation),
}

impl Sink {
    fn start(
        args: &RenderArgs,
        size: (usize, usize),
        frames: usize,
        fps: f64,
    ) -> Result<Self, CliError> {
        let output = &args.out.output;
        Ok(match Codec::of(output) {
            Some(codec) => {
                let crf = args.animation.crf.unwrap_or(ffmpeg::DEFAULT_CRF);
                Sink::Ffmpeg(Encoder::start(output, codec, size, fps, crf)?)
            }
            None => Sink::Animation(Animation::create(output, size.0, size.1, frames, fps)?),
        })
    }

    fn push(&mut self, image: &Image, rgb: &[u8]) -> Result<(), CliError> {
        match self {
            Sink::Ffmpeg(e) => Ok(e.push(rgb)?),
            Sink::Animation(a) => Ok(a.push(image)?),
        }
    }

    fn finish(self) -> Result<(), CliError> {
        match self {
            Sink::Ffmpeg(e) => Ok(e.finish()?),
            Sink::Animation(a) => a.finish().map(|_| ()).map_err(CliError::from),
        }
    }
}

/// A frame planned: its settings (before what the look leaves to the
/// volume), its look, the data it shows and its words.
struct Planned {
    settings: RenderSettings,
    look: LookOptions,
    data: DataFrame,
    title: Option<String>,
    label: Option<String>,
}

/// Renders the movie `args` ask for.
pub fn run(args: &RenderArgs) -> Result<(), CliError> {
    refuse_with_movie(args)?;
    let output = &args.out.output;
    let name = output.display().to_string();
    let sequence = AnimationKind::from_path(output) == Some(AnimationKind::PngSequence);
    if Codec::of(output).is_none() && AnimationKind::from_path(output).is_none() {
        return Err(CliError::input(format!(
            "{name}: a movie is written as .mp4 or .webm (through ffmpeg), .gif, .png (animated) or numbered PNGs (e.g. frame_%05d.png)"
        )));
    }
    if args.animation.crf.is_some() && Codec::of(output).is_none() {
        return Err(CliError::input(format!(
            "{name}: --crf sets the quality of an .mp4 or .webm movie; GIF and PNG frames are written without it"
        )));
    }
    if args.out.bit_depth != 8 {
        return Err(CliError::input(format!(
            "{name}: --bit-depth {}: movies are written at 8 bits per channel",
            args.out.bit_depth
        )));
    }
    crate::outfile::check_output(output)?;
    let tf_text = (args.view.look.tf_file())
        .map(crate::settings::read_tf_file)
        .transpose()?;
    let options = crate::settings::options(&args.view, tf_text.as_deref())?;
    let base_settings = volray_options::settings(&options).map_err(crate::settings::refused)?;
    let size = options.camera.size;
    if Codec::of(output).is_some() {
        check_size(output, size)?;
        ffmpeg::check_available(output)?;
    }
    let base = State {
        options,
        frame: args.input.frame.map(|f| f as f64),
        title: args.figure.title.clone(),
        label: args.figure.label.clone(),
    };
    let (path, fps, keys_text) = match (&args.animation.keyframes, args.animation.turntable) {
        (Some(file), _) => {
            let keys = volray_app::movie::schema::read(file, &base)
                .map_err(|e| CliError::input(format!("--keyframes {e}")))?;
            let mut keys = keys;
            if let Some(fps) = args.animation.fps {
                keys.fps = Some(fps);
            }
            let movie = Movie::new(keys, DEFAULT_FPS)
                .map_err(|e| CliError::input(format!("--keyframes {}: {e}", file.display())))?;
            let fps = movie.fps;
            let text = std::fs::read_to_string(file).unwrap_or_default();
            let file = file.clone();
            (Path::Keys { movie, file }, fps, text)
        }
        (None, Some(n)) => (
            Path::Turntable(n as usize),
            args.animation.fps.unwrap_or(DEFAULT_FPS),
            String::new(),
        ),
        (None, None) => unreachable!("wanted() checked"),
    };
    let frames = match &path {
        Path::Keys { movie, .. } => movie.frames(),
        Path::Turntable(n) => *n,
    };
    let spec = args
        .input
        .input
        .clone()
        .unwrap_or(volray_app::input::DEMO.into());
    let outputs: Vec<PathBuf> = match sequence {
        true => (0..frames)
            .filter_map(|k| volray_io::sequence_path(output, k))
            .collect(),
        false => vec![output.clone()],
    };
    let mut others: Vec<&std::path::Path> = args.view.look.tf_file().into_iter().collect();
    if let Some(file) = &args.animation.keyframes {
        others.push(file);
    }
    volray_app::reads::refuse_overwriting_inputs(&outputs, std::slice::from_ref(&spec), &others)?;

    let range = match args.animation.movie_frames {
        Some(part) => volray_app::movie::plan::part(part.start, part.end, frames)
            .map_err(|e| CliError::input(format!("--movie-frames {e}")))?,
        None => 0..frames,
    };
    let work = match args.animation.resume || args.animation.movie_frames.is_some() {
        true => Some(Work::open(
            output,
            &identity(&keys_text, frames, size),
            sequence,
            size,
        )?),
        false => None,
    };
    let pool = thread_pool(args.view.threads)?;

    // The frames to render: those of the range not kept already.
    let todo: Vec<usize> = range
        .clone()
        .filter(|&k| !work.as_ref().is_some_and(|w| w.has(k)))
        .collect();
    if let Some(w) = &work {
        let kept = range.len() - todo.len();
        if kept > 0 {
            eprintln!(
                "volray: {name}: resumed: {kept} of {} frames kept in {}, {} to render",
                range.len(),
                w.dir().display(),
                todo.len()
            );
        }
    }
    let job = Job {
        args,
        path,
        base,
        base_settings,
        frames,
        todo,
        pool,
    };
    let sink = match &work {
        None => Some(Sink::start(args, size, frames, fps)?),
        Some(_) => None,
    };
    let mut out = Out {
        work,
        sink,
        bar: frame_bar(job.todo.len() as u64),
        rendered: 0,
        interrupt_after: test_interrupt_after(),
    };
    // The level (and whether the volume is read whole) for the first frame.
    match crate::session::plan(&args.input, &args.view, &job.base_settings)? {
        Plan::Whole { level } => render_whole(&job, &args.input.at_level(level), &mut out)?,
        Plan::Streamed(streamed) => render_streamed(&job, *streamed, &mut out)?,
    }
    out.bar.finish_and_clear();
    match (out.work, out.sink) {
        (None, Some(sink)) => sink.finish(),
        (Some(work), _) => {
            let missing = (0..frames).filter(|&k| !work.has(k)).count();
            if missing > 0 {
                eprintln!(
                    "volray: {name}: frames {}:{} rendered into {}; {missing} of {frames} still missing: render them (--movie-frames A:B) or run again with --resume to finish",
                    range.start,
                    range.end,
                    work.dir().display()
                );
                return Ok(());
            }
            if !sequence {
                let bar = frame_bar(frames as u64);
                let mut sink = Sink::start(args, size, frames, fps)?;
                for k in 0..frames {
                    let rgb = work.load(k)?;
                    sink.push(&image_of(&rgb, size), &rgb)?;
                    bar.inc(1);
                }
                bar.finish_and_clear();
                sink.finish()?;
            }
            Ok(work.remove()?)
        }
        (None, None) => unreachable!("a sink or a work folder"),
    }
}

/// What every frame of a movie needs.
struct Job<'a> {
    args: &'a RenderArgs,
    path: Path,
    base: State,
    base_settings: RenderSettings,
    frames: usize,
    /// The frames to render, in order.
    todo: Vec<usize>,
    pool: rayon::ThreadPool,
}

/// Where the rendered frames go: the work folder, else the output.
struct Out {
    work: Option<Work>,
    sink: Option<Sink>,
    bar: ProgressBar,
    rendered: usize,
    interrupt_after: Option<usize>,
}

impl Out {
    /// Frame `k`, rendered and annotated, handed on at once.
    fn put(&mut self, k: usize, image: &Image) -> Result<(), CliError> {
        let mut rgb = Vec::new();
        volray_io::rgb8(image, &mut rgb);
        match (&self.work, &mut self.sink) {
            (Some(w), _) => w.save(k, image, &rgb)?,
            (None, Some(s)) => s.push(image, &rgb)?,
            (None, None) => unreachable!("a sink or a work folder"),
        }
        self.bar.inc(1);
        self.rendered += 1;
        if self.interrupt_after == Some(self.rendered) {
            interrupt_self();
        }
        Ok(())
    }
}

/// The frames of a volume read whole, in runs that show one time point:
/// the time point read (two, blended), what the look leaves to it, its
/// renderer built once for the run.
fn render_whole(job: &Job, input_args: &InputArgs, out: &mut Out) -> Result<(), CliError> {
    let (args, todo) = (job.args, &job.todo);
    let mut centre = None;
    let mut at = 0;
    while at < todo.len() {
        let first_data = data_of(&job.path, todo[at], &job.base, centre.unwrap_or([0.0; 3]));
        let mut input = load_data(input_args, args, first_data)?;
        let c = *centre.get_or_insert(input.volume.centre().to_array());
        let mut planned = Vec::new();
        let mut end = at;
        while end < todo.len() {
            let p = plan_frame(job, todo[end], c)?;
            if p.data != first_data && end > at {
                break;
            }
            planned.push(p);
            end += 1;
        }
        // What the look leaves to this volume, for each frame (kept while
        // the look stays: `tf auto`'s histogram is taken once).
        let mut last: Option<(LookOptions, TransferFunction, TransferFunction)> = None;
        for p in &mut planned {
            let tf = p.settings.transfer_function.clone();
            match &last {
                Some((look, before, after)) if *look == p.look && *before == tf => {
                    p.settings.transfer_function = after.clone();
                }
                _ => {
                    let slot = &mut p.settings.transfer_function;
                    volray_app::look::leave_to_volume(&p.look, slot, &mut input)
                        .map_err(crate::settings::refused)?;
                    last = Some((p.look.clone(), tf, p.settings.transfer_function.clone()));
                }
            }
        }
        // Built for the run's most demanding frame (the smallest room
        // left for caches): every frame within --max-memory, checked
        // before the first is rendered.
        let mut worst = (usize::MAX, 0);
        for (i, p) in planned.iter().enumerate() {
            let room = crate::session::cache_budget(&args.view, &p.settings, &input)?;
            worst = worst.min((room, i));
        }
        let renderer = renderer_for(&args.view, &planned[worst.1].settings, &input)?;
        for (p, &k) in planned.iter().zip(&todo[at..end]) {
            let mut image = (job.pool)
                .install(|| renderer.render(FrameRequest::new(&p.settings)))
                .map(Rendered::image)
                .map_err(|e| crate::session::render_failure(&args.view, &input.name, e))?;
            let words = (p.title.clone(), p.label.clone());
            crate::figure::draw_titled(args, &p.settings, &renderer, &input, words, &mut image)?;
            out.put(k, &image)?;
        }
        at = end;
    }
    Ok(())
}

/// The frames of a volume too large to read whole, each rendered piece
/// by piece within `--max-memory` as a still would be (one time point:
/// a `frame` that moves needs the volume read whole; annotations are not
/// drawn into pieces yet).
fn render_streamed(job: &Job, mut streamed: StreamedInput, out: &mut Out) -> Result<(), CliError> {
    let args = job.args;
    crate::figure::refuse(&args.figure, "a volume rendered piece by piece")?;
    let (lo, hi) = streamed.streamed.grid().bounds();
    let centre = ((lo + hi) / 2.0).to_array();
    let mut last = None;
    for &k in &job.todo {
        let p = plan_frame(job, k, centre)?;
        if p.data != DataFrame::At(args.input.frame) {
            return Err(CliError::input(format!(
                "--keyframes: frame {k}: \"frame\" moves the time point of {}, which is rendered piece by piece within --max-memory: a moving time point needs the volume read whole (raise --max-memory or give a coarser --level)",
                streamed.name
            )));
        }
        if p.title.is_some() || p.label.is_some() {
            return Err(CliError::input(
                "--keyframes: title and label are drawn into frames of a volume read whole; not into a volume rendered piece by piece yet",
            ));
        }
        let settings = (streamed.settings_from_volume(&p.look, p.settings))
            .map_err(|e| app_failure(&args.view, e))?;
        let (image, times) = (job.pool)
            .install(|| streamed.render(&settings, &|_| {}))
            .map_err(|e| app_failure(&args.view, e))?;
        out.put(k, &image)?;
        last = Some(times);
    }
    if let Some(times) = last {
        let n = job.todo.len();
        eprintln!(
            "{} (the last of {n} frames)",
            streamed_note(&streamed, &times)
        );
    }
    Ok(())
}

/// Refuses what a movie does not take.
fn refuse_with_movie(args: &RenderArgs) -> Result<(), CliError> {
    let a = &args.animation;
    let refuse = |what: &str| Err(CliError::input(what.to_string()));
    if a.keyframes.is_some() && a.turntable.is_some() {
        return refuse(
            "--keyframes and --turntable each make a movie: give one (a turntable is keyframes of the azimuth, docs/movies.md)",
        );
    }
    if args.scene.is_scene() {
        return refuse(
            "--keyframes renders one volume: --channels and --overlay are not animated yet",
        );
    }
    if args.scene.frames.is_some() {
        return refuse(
            "--frames animates the time points one by one: with --keyframes give \"frame\" in the keyframes",
        );
    }
    if !a.series.is_empty() {
        return refuse("a movie renders one input: give one");
    }
    Ok(())
}

/// The data frame `k` shows.
fn data_of(path: &Path, k: usize, base: &State, centre: [f64; 3]) -> DataFrame {
    match path {
        Path::Keys { movie, .. } => movie.data_frame(&movie.at(k, centre)),
        Path::Turntable(_) => DataFrame::At(base.frame.map(|f| f as usize)),
    }
}

/// Frame `k`'s settings, look, data and words; `centre` is the point
/// looked at by default.
fn plan_frame(job: &Job, k: usize, centre: [f64; 3]) -> Result<Planned, CliError> {
    Ok(match &job.path {
        Path::Keys { movie, .. } => {
            let state = movie.at(k, centre);
            Planned {
                settings: volray_options::settings(&state.options)
                    .map_err(|e| keys_failure(&job.path, k, e))?,
                data: movie.data_frame(&state),
                look: state.options.look,
                title: state.title,
                label: state.label,
            }
        }
        Path::Turntable(_) => Planned {
            settings: turntable_frame(&job.base_settings, k, job.frames),
            look: job.base.options.look.clone(),
            data: DataFrame::At(job.base.frame.map(|f| f as usize)),
            title: job.base.title.clone(),
            label: job.base.label.clone(),
        },
    })
}

/// An interpolated frame's options refused (a mix the checks do not take).
fn keys_failure(path: &Path, k: usize, e: volray_options::OptionError) -> CliError {
    let file = match path {
        Path::Keys { file, .. } => file.display().to_string(),
        Path::Turntable(_) => "--turntable".into(),
    };
    CliError::input(format!(
        "--keyframes {file}: frame {k}: {}",
        e.message(&volray_flags::Flags)
    ))
}

/// The volume a frame shows: a time point, or two blended.
fn load_data(
    input_args: &InputArgs,
    args: &RenderArgs,
    data: DataFrame,
) -> Result<Input, CliError> {
    let at = |frame: Option<usize>| InputArgs {
        frame,
        ..input_args.clone()
    };
    let log = args.view.look.log;
    match data {
        DataFrame::At(None) => load(input_args, log),
        DataFrame::At(Some(i)) => load(&at(Some(i)), log),
        DataFrame::Between(i, w) => {
            let a = load(&at(Some(i)), log)?;
            let b = load(&at(Some(i + 1)), log)?;
            let volume = volray_app::movie::time::blend(&a.volume, &b.volume, w)
                .map_err(|e| CliError::input(format!("{}: {e}", a.name)))?;
            Ok(Input {
                volume,
                name: format!("{} (time point {})", a.name, i as f64 + w),
                ..a
            })
        }
    }
}

/// What the run is, for its work folder: the command's words (less those
/// that choose which frames or how many threads, which change no pixel),
/// the keyframes file's text, the frame count and size.
fn identity(keys: &str, frames: usize, size: (usize, usize)) -> String {
    let words = std::env::args_os().skip(1);
    let words: Vec<String> = words.map(|w| w.to_string_lossy().into_owned()).collect();
    volray_app::movie::work::identity_of(&words, keys, frames, size)
}

/// A kept frame back as an image (opaque; its 8-bit values exactly).
fn image_of(rgb: &[u8], (w, h): (usize, usize)) -> Image {
    let pixels = rgb
        .chunks_exact(3)
        .map(|c| [0, 1, 2].map(|i| f32::from(c[i]) / 255.0))
        .map(|[r, g, b]| [r, g, b, 1.0])
        .collect();
    Image::from_pixels(w, h, pixels).expect("a frame of the movie's size")
}

/// A progress bar of frames on a terminal: frames done, the rate and the
/// time left.
fn frame_bar(frames: u64) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(frames);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} frame {pos}/{len} [{bar:30}] {per_sec} ({eta} left)",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    bar
}

/// For the tests of `--resume`: `VOLRAY_TEST_INTERRUPT_AFTER=N` sends
/// this process SIGINT once N frames are rendered, as Ctrl-C would.
fn test_interrupt_after() -> Option<usize> {
    std::env::var("VOLRAY_TEST_INTERRUPT_AFTER")
        .ok()?
        .parse()
        .ok()
}

#[cfg(unix)]
fn interrupt_self() {
    let _ = signal_hook::low_level::raise(signal_hook::consts::SIGINT);
    // The signal thread deletes the unfinished files and exits.
    std::thread::sleep(std::time::Duration::from_secs(10));
}

#[cfg(not(unix))]
fn interrupt_self() {}

/// A movie's frames have even sides (ffmpeg's `check_size`), refused
/// naming `--size`.
fn check_size(output: &std::path::Path, (w, h): (usize, usize)) -> Result<(), CliError> {
    ffmpeg::check_size(output, w, h).map_err(|_| {
        CliError::input(format!(
            "{}: --size {w}x{h}: a movie's frames have even sides (H.264 and VP9 at 4:2:0 halve the colour's resolution); give e.g. --size {}x{}",
            output.display(),
            w + w % 2,
            h + h % 2
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kept_frames_come_back_as_the_bytes_they_were() {
        let image =
            Image::from_pixels(2, 1, vec![[0.1, 0.5, 0.99, 1.0], [0.0, 1.0, 0.731, 0.5]]).unwrap();
        let (mut rgb, mut back) = (Vec::new(), Vec::new());
        volray_io::rgb8(&image, &mut rgb);
        volray_io::rgb8(&image_of(&rgb, (2, 1)), &mut back);
        assert_eq!(back, rgb);
        assert_eq!(rgb, [26, 128, 252, 0, 255, 186]);
    }

    #[test]
    fn movie_names_pick_the_codec_and_sides_must_be_even() {
        use std::path::Path as P;
        assert_eq!(Codec::of(P::new("a/m.MP4")), Some(Codec::Mp4));
        assert_eq!(Codec::of(P::new("m.webm")), Some(Codec::Webm));
        assert_eq!(Codec::of(P::new("m.gif")), None);
        assert!(check_size(P::new("m.mp4"), (64, 48)).is_ok());
        let odd = check_size(P::new("m.mp4"), (65, 48)).unwrap_err();
        assert!(
            odd.message.contains("--size 65x48") && odd.message.contains("66x48"),
            "{}",
            odd.message
        );
    }
}
