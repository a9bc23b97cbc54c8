//! What the options leave to the volume itself: with labels, the volume
//! marked as a label volume and the labels' transfer function; otherwise,
//! where [`LookOptions::auto_tf`] says so, the transfer function chosen
//! from the volume's histogram. Called once the volume is read (and, with
//! the log option, turned into its log10).

use crate::error::OptionError;
use crate::option::Opt;
use crate::options::{LookOptions, Tf};
use volray_core::transfer::{auto, labels};
use volray_core::{TransferFunction, Volume};

/// The file's own display window (an OME-Zarr image's `omero` window of
/// the channel read) as the default range: the transfer function's domain
/// where `look` leaves it to the volume (no range, no transfer function
/// or preset with a domain of its own; not labels, and not log, whose
/// domain is taken before the file is read). The automatic transfer
/// function then chooses within the window, as within a range. What
/// napari-ome-zarr and vizarr show as the contrast limits. Call it before
/// [`from_volume`].
///
/// ```
/// use volray_core::TransferFunction;
/// use volray_options::{LookOptions, file_window};
///
/// let mut tf = TransferFunction::default();
/// file_window(&LookOptions::default(), &mut tf, Some((100.0, 900.0)));
/// assert_eq!(tf.domain, Some((100.0, 900.0)));
/// // A range given wins: its domain is set before.
/// let mut tf = TransferFunction { domain: Some((0.0, 50.0)), ..TransferFunction::default() };
/// file_window(&LookOptions::default(), &mut tf, Some((100.0, 900.0)));
/// assert_eq!(tf.domain, Some((0.0, 50.0)));
/// ```
pub fn file_window(
    look: &LookOptions,
    transfer_function: &mut TransferFunction,
    window: Option<(f64, f64)>,
) {
    if transfer_function.domain.is_none() && !look.labels && !look.log {
        transfer_function.domain = window;
    }
}

/// Puts into `transfer_function` (and `volume`) what `look` leaves to the
/// volume `name` (for messages): labels or the automatic choice.
pub fn from_volume(
    look: &LookOptions,
    transfer_function: &mut TransferFunction,
    volume: &mut Volume,
    name: &str,
) -> Result<(), OptionError> {
    if !look.labels {
        choose_auto(look, transfer_function, volume);
        return Ok(());
    }
    let found = volume_labels(volume, name)?;
    volume.set_labels(true);
    label_transfer_function(look, transfer_function, &found, name)
}

/// The labels of `volume` (`name`), refused where it is not a label
/// volume.
pub fn volume_labels(volume: &Volume, name: &str) -> Result<Vec<i64>, OptionError> {
    labels_found(labels::labels_of(volume, labels::MAX_LABELS), name)
}

/// The labels found in the volume `name` (by [`labels::labels_of`] with
/// [`labels::MAX_LABELS`], in one process or joined across the ranks of
/// a distributed one), refused where it is not a label volume.
pub fn labels_found(
    found: Result<Option<Vec<i64>>, labels::LabelError>,
    name: &str,
) -> Result<Vec<i64>, OptionError> {
    let refused = |error: String| OptionError::Labels {
        volume: name.to_string(),
        opts: &[Opt::Labels],
        error,
    };
    found.map_err(|e| refused(e.to_string()))?.ok_or_else(|| {
        refused(format!(
            "more than {} distinct values: not a label volume",
            labels::MAX_LABELS
        ))
    })
}

/// With labels, the transfer function of `found` (the labels of the
/// volume or volumes `name`) with the label opacities and the shown
/// subset, unless a transfer function is given, which then gives it.
pub fn label_transfer_function(
    look: &LookOptions,
    transfer_function: &mut TransferFunction,
    found: &[i64],
    name: &str,
) -> Result<(), OptionError> {
    let styled = look.label_opacity.is_some() || look.show_labels.is_some();
    match &look.tf {
        Some(Tf::Auto) => Err(OptionError::AutoWithLabels),
        Some(_) if styled => Err(OptionError::LabelStyleWithTf),
        Some(_) => Ok(()),
        None if look.range.is_some() => Err(OptionError::RangeWithLabels),
        None => {
            let style = labels::LabelStyle {
                opacity: look.label_opacity.clone().unwrap_or_default(),
                shown: look.show_labels.clone(),
                colours: look.label_colours.clone(),
            };
            *transfer_function = labels::transfer_function(found, &style).map_err(|e| {
                let opts: &'static [Opt] = match e {
                    labels::LabelError::Absent(..) => &[Opt::LabelOpacity, Opt::ShowLabels],
                    _ => &[Opt::Labels],
                };
                OptionError::Labels {
                    volume: name.to_string(),
                    opts,
                    error: e.to_string(),
                }
            })?;
            Ok(())
        }
    }
}

/// Whether the automatic transfer function renders `volume` as its log10
/// (as the log option does): where [`LookOptions::auto_tf`] says so, no
/// window is given (`transfer_function` has no domain: no range, no
/// file's window), neither the log option nor [`LookOptions::linear`] is
/// given, the volume is not labels, and its values span decades
/// (volray-core's [`auto::volume_spans_decades`]). The caller takes the log10
/// and says so ([`auto_log_note`]); a volume read piece by piece or
/// across ranks, a series and a scene keep their values.
///
/// ```
/// use volray_core::{TransferFunction, Volume};
/// use volray_options::{LookOptions, chooses_log};
///
/// // Values 4096/n for n = 1..=4096: as many above v as 4096/v, as a
/// // density falling as r⁻³ about a point.
/// let data = (1..=4096).map(|n| 4096.0 / n as f32).collect();
/// let v = Volume::new([16, 16, 16], data).unwrap();
/// let tf = TransferFunction::default();
/// assert!(chooses_log(&LookOptions::default(), &tf, &v));
/// let linear = LookOptions { linear: true, ..LookOptions::default() };
/// assert!(!chooses_log(&linear, &tf, &v));
/// let ranged = TransferFunction { domain: Some((1.0, 1e6)), ..TransferFunction::default() };
/// assert!(!chooses_log(&LookOptions::default(), &ranged, &v));
/// ```
pub fn chooses_log(
    look: &LookOptions,
    transfer_function: &TransferFunction,
    volume: &Volume,
) -> bool {
    look.auto_tf()
        && !look.log
        && !look.linear
        && !look.labels
        && !volume.is_labels()
        && transfer_function.domain.is_none()
        && auto::volume_spans_decades(volume)
}

/// The note a front end prints when [`chooses_log`] chose the log10 of
/// the volume `name`; `linear` says how to keep the values (`--linear`,
/// `log=False`).
pub fn auto_log_note(name: &str, linear: &str) -> String {
    format!(
        "note: {name}: the values span decades (half of those above the background lie in the \
         lowest {} % of a linear ramp): rendering their log10, as with log; {linear} or a range \
         keeps the values",
        auto::LOG_MEDIAN * 100.0
    )
}

/// Where [`LookOptions::auto_tf`] says so, the transfer function chosen
/// from `volume`'s histogram (volray-core's [`auto`]) over
/// `transfer_function`'s window: its opacity unless the opacity ramp is
/// given, its colours unless a colour map is. `volume` is what the
/// renderer sees (with the log option, the log10 of the data), and the
/// window is in its units, as [`crate::settings()`] leaves it.
pub fn choose_auto(look: &LookOptions, transfer_function: &mut TransferFunction, volume: &Volume) {
    if !look.auto_tf() {
        return;
    }
    // A volume with no finite value is refused later, by the renderer.
    if let Some(robust) = auto::robust_histogram_of(volume) {
        apply_auto(look, transfer_function, &robust);
    }
}

/// The transfer function chosen from values whose statistics are
/// `robust` (volray-core's [`auto::robust_histogram`]), put into
/// `transfer_function` as [`choose_auto`] says (a series chooses from its
/// first volume's histogram): where the histogram was refined to a window
/// narrower than the data's range and no window is given, the window
/// becomes the domain, so that outliers above it take the top colour.
pub fn apply_auto(
    look: &LookOptions,
    transfer_function: &mut TransferFunction,
    robust: &auto::Robust,
) {
    let chosen = auto::robust_transfer_function(robust, transfer_function.domain);
    transfer_function.domain = chosen.domain;
    if look.opacity.is_none() {
        transfer_function.opacity = chosen.opacity;
    }
    if transfer_function.color.is_none() {
        transfer_function.color = chosen.color;
    }
}
