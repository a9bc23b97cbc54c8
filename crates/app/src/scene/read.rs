//! The volumes of a picture read, each whole with its look ([`Layer`]):
//! INPUT or its channels (each in its colour as a constant colour
//! transfer function, its opacity chosen from its own histogram by
//! default, its own value window unless a range is given), then each
//! overlay with its own options and the shared shading; every volume read
//! under what the volumes before it left of the memory limit ([`Budget`]).
//!
//! Each look is built as the first volume's is, by volray-options. The
//! refusals are typed ([`LayerError`]) so that each front end words a
//! reader's error in its own syntax before the words added here.

use super::{Budget, ChannelAxis, LayerSource, OverlaySpec, Refused, channel_axis, channel_color};
use crate::AppError;
use crate::input::{self, Input, Request};
use crate::look::leave_to_volume;
use volray_core::RenderSettings;
use volray_core::scene::{Look, overlaps};
use volray_options::{LookOptions, OptionError, Options};

/// One volume of the picture: what was read, its settings alone (whose
/// look becomes its [`Look`]), and where it came from.
pub struct Layer {
    pub input: Input,
    pub settings: RenderSettings,
    pub source: LayerSource,
}

impl Layer {
    /// Its look in the picture: shown unless an overlay's `hidden`.
    pub fn look(&self) -> Look {
        Look {
            visible: self.source.visible(),
            ..Look::of(&self.settings)
        }
    }
}

/// Why a volume of the picture was refused.
#[derive(Debug)]
pub enum Failure {
    /// The reader's error for INPUT or a channel.
    Read(AppError),
    /// The reader's error for an overlay (the front end says `--overlay`
    /// before it).
    OverlayRead(AppError),
    /// What the look leaves to the volume refused (`labels`, `tf auto`).
    Option(OptionError),
    /// A refusal in one line.
    Refused(Refused),
}

/// A volume refused, and, where it was read after others, the budget
/// they left it ([`Budget::explain`] says what they hold).
#[derive(Debug)]
pub struct LayerError {
    /// Boxed: a reader's error is large beside the layers returned.
    pub failure: Box<Failure>,
    pub after: Option<Budget>,
}

impl From<Failure> for LayerError {
    fn from(failure: Failure) -> Self {
        LayerError {
            failure: Box::new(failure),
            after: None,
        }
    }
}

impl From<Refused> for LayerError {
    fn from(e: Refused) -> Self {
        Failure::Refused(e).into()
    }
}

/// `e`, a refusal of the next volume, with the budget it was read under.
fn explained(budget: &Budget, e: LayerError) -> LayerError {
    LayerError {
        after: Some(budget.clone()),
        ..e
    }
}

/// How INPUT is read and looked at: its request, `log`, the shared look.
pub struct First<'a> {
    pub request: &'a Request,
    pub log: bool,
    pub look: &'a LookOptions,
}

/// The channels asked for: `which` (`None`: all), their colours (`None`:
/// the palette).
#[derive(Clone, Copy)]
pub struct ChannelPick<'a> {
    pub which: Option<&'a [usize]>,
    pub colors: Option<&'a [[f32; 3]]>,
}

/// The overlays: their specs, their `tf=` files' texts (read by the
/// front end), and the shared options without the first volume's
/// transfer function.
pub struct Overlays<'a> {
    pub specs: &'a [OverlaySpec],
    pub tf_texts: &'a [Option<String>],
    pub shared: &'a Options,
}

/// `request` reading volume `index` along `axis`.
pub fn pick(axis: ChannelAxis, request: &Request, index: usize) -> Request {
    let mut one = request.clone();
    axis.pick(&mut one.channel, &mut one.frame, index);
    one
}

/// The volumes of the picture, each read whole with its look: INPUT (read
/// as `first` says) or its `channels`, then each overlay, refused where an
/// overlay does not meet the first volume.
pub fn read_layers(
    first: &First<'_>,
    channels: Option<ChannelPick<'_>>,
    overlays: &Overlays<'_>,
    settings: &RenderSettings,
) -> Result<Vec<Layer>, LayerError> {
    let mut budget = Budget::new(first.request.max_memory);
    let mut layers = match channels {
        Some(which) => read_channels(first, which, settings, &mut budget)?,
        None => {
            let mut input = input::load_log(first.request, first.log).map_err(Failure::Read)?;
            budget.add(&input.volume);
            let mut settings = settings.clone();
            leave_to_volume(first.look, &mut settings.transfer_function, &mut input)
                .map_err(Failure::Option)?;
            vec![Layer {
                input,
                settings,
                source: LayerSource::Input,
            }]
        }
    };
    for (overlay, tf_text) in overlays.specs.iter().zip(overlays.tf_texts) {
        let mut layer = load_overlay(overlay, overlays.shared, budget.left(), tf_text.as_deref())
            .map_err(|e| explained(&budget, e))?;
        budget.add(&layer.input.volume);
        layer.input.max_memory = budget.limit;
        let first = &layers[0].input;
        if !overlaps(&layer.input.volume, &first.volume) {
            let ((a, b), (c, d)) = (layer.input.volume.bounds(), first.volume.bounds());
            return Err(Refused(format!(
                "--overlay {}: its box ({a} .. {b}) does not meet the box of {} ({c} .. {d}): check its origin and spacing",
                overlay.spec, first.name
            ))
            .into());
        }
        layers.push(layer);
    }
    Ok(layers)
}

/// The channels `which` of INPUT (read as `first` says: at the time
/// point its `frame` picks), each with its look.
fn read_channels(
    first: &First<'_>,
    which: ChannelPick<'_>,
    settings: &RenderSettings,
    budget: &mut Budget,
) -> Result<Vec<Layer>, LayerError> {
    let request = first.request;
    let spec = &request.spec.name();
    if volray_data::is_source_spec(spec) {
        return Err(Refused(format!(
            "--channels: {spec} is a built-in source, one volume: give a file holding several channels"
        ))
        .into());
    }
    let log = first.log;
    if request.channel.is_some() {
        return Err(Refused(format!(
            "--channels picks the channels of {spec}; --channel picks one: give one of them"
        ))
        .into());
    }
    // Channel 0 (at the time point the frame picks) tells how many the
    // file holds; kept if asked for, else dropped before the others are
    // read, and no longer counted against the memory limit.
    let channel_0 = input::load_log(request, log).map_err(Failure::Read)?;
    budget.add(&channel_0.volume);
    let Some((_, info)) = &channel_0.file else {
        return Err(Refused(format!(
            "--channels: {spec} is not a file holding several channels"
        ))
        .into());
    };
    let (count, axis) = channel_axis(info);
    if axis == ChannelAxis::Time && request.frame.is_some() {
        return Err(Refused(format!(
            "--channels renders the {count} volumes of {spec} (one channel, {count} time points) together; --frame picks one: give one of them"
        ))
        .into());
    }
    let (indices, colors) = super::picked_channels(which.colors, which.which, spec, count)?;
    let mut kept = Some(channel_0);
    if !indices.contains(&0) {
        budget.remove(&kept.take().expect("channel 0 read").volume);
    }
    let mut layers = Vec::with_capacity(indices.len());
    for (&index, &rgb) in indices.iter().zip(&colors) {
        let this = if index == 0 { kept.take() } else { None };
        let mut input = match this {
            Some(input) => input,
            None => {
                let mut one = pick(axis, request, index);
                one.max_memory = budget.left();
                let mut input = input::load_log(&one, log)
                    .map_err(|e| explained(budget, Failure::Read(e).into()))?;
                budget.add(&input.volume);
                input.max_memory = budget.limit;
                input
            }
        };
        input.name = format!("{spec} (channel {index})");
        let mut settings = settings.clone();
        let tf = &mut settings.transfer_function;
        tf.color = Some(channel_color(rgb, settings.blend.is_projection()));
        leave_to_volume(first.look, tf, &mut input).map_err(Failure::Option)?;
        layers.push(Layer {
            input,
            settings,
            source: LayerSource::Channel { index, axis },
        });
    }
    Ok(layers)
}

/// The channels of `looks` (read first, at another time point) at time
/// point `t` of the file `request` names, each with its look.
pub fn channels_at(
    request: &Request,
    log: bool,
    t: usize,
    looks: &[(LayerSource, RenderSettings)],
) -> Result<Vec<Layer>, LayerError> {
    let spec = request.spec.name();
    let at = Request {
        frame: Some(t),
        ..request.clone()
    };
    let mut budget = Budget::new(at.max_memory);
    let mut layers = Vec::with_capacity(looks.len());
    for (source, settings) in looks {
        let LayerSource::Channel { index, axis } = source else {
            unreachable!("--frames takes channels only");
        };
        let mut one = pick(*axis, &at, *index);
        one.max_memory = budget.left();
        let mut input =
            input::load_log(&one, log).map_err(|e| explained(&budget, Failure::Read(e).into()))?;
        budget.add(&input.volume);
        input.max_memory = budget.limit;
        input.name = format!("{spec} (channel {index}, time point {t})");
        layers.push(Layer {
            input,
            settings: settings.clone(),
            source: source.clone(),
        });
    }
    Ok(layers)
}

/// The overlay read, with its look.
fn load_overlay(
    overlay: &OverlaySpec,
    shared: &Options,
    max_memory: Option<u64>,
    tf_text: Option<&str>,
) -> Result<Layer, LayerError> {
    let refuse = |e| Failure::Refused(overlay.refused(e));
    let request = Request {
        frame: overlay.frame,
        channel: overlay.channel,
        max_memory,
        ..Request::of(&overlay.file)
    };
    let mut input = input::load_log(&request, false).map_err(Failure::OverlayRead)?;
    // The shared options without the first volume's transfer function
    // (whose text is not read here): the overlay's look is its own
    // options'.
    let (look, mut settings) = overlay.settings(shared.clone(), tf_text)?;
    leave_to_volume(&look, &mut settings.transfer_function, &mut input).map_err(refuse)?;
    Ok(Layer {
        input,
        settings,
        source: LayerSource::Overlay(overlay.clone()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The volumes of `request` (its channels if `channels`) and `overlays`.
    fn read(
        request: &str,
        channels: bool,
        overlays: &[OverlaySpec],
    ) -> Result<Vec<Layer>, LayerError> {
        let request = Request::of(request);
        let shared = Options::default();
        let first = First {
            request: &request,
            log: false,
            look: &shared.look,
        };
        let pick = ChannelPick {
            which: None,
            colors: None,
        };
        let tf_texts = vec![None; overlays.len()];
        let overlays = Overlays {
            specs: overlays,
            tf_texts: &tf_texts,
            shared: &shared,
        };
        read_layers(
            &first,
            channels.then_some(pick),
            &overlays,
            &RenderSettings::default(),
        )
    }

    #[test]
    fn a_built_in_source_is_read_with_its_look_and_its_channels_are_refused() {
        let layers = read("blobs:16", false, &[]).unwrap();
        assert_eq!(layers.len(), 1);
        assert_eq!(layers[0].source, LayerSource::Input);
        assert_eq!(layers[0].input.volume.dims(), [16; 3]);
        let e = read("blobs:16", true, &[]).err().unwrap();
        match *e.failure {
            Failure::Refused(Refused(m)) => assert_eq!(
                m,
                "--channels: blobs:16 is a built-in source, one volume: give a file holding several channels"
            ),
            other => panic!("{other:?}"),
        }
        assert!(e.after.is_none());
    }

    #[test]
    fn an_overlay_the_reader_refuses_says_what_the_volumes_before_it_hold() {
        let dir = tempfile::tempdir().unwrap();
        let junk = dir.path().join("junk.txt");
        std::fs::write(&junk, "not a volume").unwrap();
        let spec = OverlaySpec::parse(junk.to_str().unwrap()).unwrap();
        let e = read("blobs:16", false, &[spec]).err().unwrap();
        assert!(
            matches!(*e.failure, Failure::OverlayRead(AppError::Io(_))),
            "{:?}",
            e.failure
        );
        // blobs:16 is held in memory: 16³ f32 samples.
        let budget = e.after.expect("read after the first volume");
        assert!(
            budget
                .explain("refused")
                .starts_with("refused (the volumes read before it hold 16 KiB of --max-memory"),
            "{}",
            budget.explain("refused")
        );
    }
}
