//! An overlay (`--overlay FILE[:OPTIONS]`): another volume in the
//! picture, placed by its world coordinates, with its own look after a
//! ':' (`labels`, `colormap=`, `preset=`, `range=`, `opacity=`, `tf=`,
//! `frame=`, `channel=`, `hidden`): the spec parsed, and its look and
//! settings built as the first volume's are, by volray-options, with the
//! shared shading. The front end reads its file (and its `tf=` file).

use super::Refused;
use crate::words::{parse_opacity, parse_range};
use volray_core::RenderSettings;
use volray_options::{LookOptions, Naming, Opt, OptionError, Options, Tf};

/// The overlay options, as the refusal of an unknown one lists them.
pub const OVERLAY_OPTIONS: &str = "labels, colormap=NAME, preset=NAME, range=LO,HI, opacity=P,Q, tf=FILE.json, frame=N, channel=N, hidden";

/// An `--overlay FILE[:OPTIONS]`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct OverlaySpec {
    /// As given, for messages.
    pub spec: String,
    pub file: String,
    pub labels: bool,
    pub colormap: Option<String>,
    pub preset: Option<String>,
    pub range: Option<(f64, f64)>,
    pub opacity: Option<(f32, f32)>,
    pub tf: Option<String>,
    pub frame: Option<usize>,
    /// OME-Zarr's `c` (as `--channel`).
    pub channel: Option<usize>,
    /// Placed and framed, not drawn (`Look::visible`).
    pub hidden: bool,
}

impl OverlaySpec {
    /// Parses `spec`: the options are after the last ':' whose remainder
    /// reads as options (so `file.h5:/dataset` stays a file spec).
    pub fn parse(spec: &str) -> Result<Self, Refused> {
        let (file, options) = (spec.char_indices().rev())
            .filter(|&(_, c)| c == ':')
            .find_map(|(at, _)| option_tokens(&spec[at + 1..]).map(|o| (&spec[..at], o)))
            .unwrap_or((spec, Vec::new()));
        let mut parsed = OverlaySpec {
            spec: spec.to_string(),
            file: file.to_string(),
            ..Default::default()
        };
        let refuse = |message: String| Refused(format!("--overlay {spec}: {message}"));
        let mut seen: Vec<&str> = Vec::new();
        for (name, value) in &options {
            if seen.contains(&name.as_str()) {
                return Err(refuse(format!("option \"{name}\" is given twice")));
            }
            seen.push(name);
            let value = match (name.as_str(), value) {
                ("labels", None) => {
                    parsed.labels = true;
                    continue;
                }
                ("hidden", None) => {
                    parsed.hidden = true;
                    continue;
                }
                ("labels" | "hidden", Some(_)) => {
                    return Err(refuse(format!("{name} takes no value")));
                }
                (_, Some(v)) => v.as_str(),
                _ => unreachable!("only labels and hidden are bare words"),
            };
            let bad = |e: String| refuse(format!("{name}={value}: {e}"));
            match name.as_str() {
                "colormap" => parsed.colormap = Some(value.to_string()),
                "preset" => parsed.preset = Some(value.to_string()),
                "range" => parsed.range = Some(parse_range(value).map_err(bad)?),
                "opacity" => parsed.opacity = Some(parse_opacity(value).map_err(bad)?),
                "tf" => parsed.tf = Some(value.to_string()),
                "frame" => {
                    parsed.frame = Some(
                        value
                            .trim()
                            .parse()
                            .map_err(|_| bad("not a frame number (from 0)".to_string()))?,
                    )
                }
                "channel" => {
                    parsed.channel = Some(
                        value
                            .trim()
                            .parse()
                            .map_err(|_| bad("not a channel number (from 0)".to_string()))?,
                    )
                }
                _ => {
                    return Err(refuse(format!(
                        "unknown option \"{name}\" ({OVERLAY_OPTIONS})"
                    )));
                }
            }
        }
        if parsed.file.is_empty() {
            return Err(refuse("no file before the options".to_string()));
        }
        Ok(parsed)
    }

    /// Its options' look (with the shared options `shared`: the flags
    /// but the first volume's transfer function, whose text is not read
    /// here) and settings, before anything is chosen from its volume.
    pub fn settings(
        &self,
        shared: Options,
        tf_text: Option<&str>,
    ) -> Result<(LookOptions, RenderSettings), Refused> {
        let look = LookOptions {
            opacity: self.opacity,
            tf: self.tf.as_ref().map(|path| Tf::Json {
                source: path.clone(),
                text: tf_text.unwrap_or_default().to_string(),
            }),
            preset: self.preset.clone(),
            colormap: self.colormap.clone(),
            labels: self.labels,
            label_opacity: None,
            show_labels: None,
            // The first volume's file's colours are not the overlay's.
            label_colours: Vec::new(),
            range: self.range,
            iso: None,
            iso_thickness: None,
            log: false,
            blend: match shared.look.blend {
                volray_options::BlendMode::Iso => volray_options::BlendMode::Composite,
                blend => blend,
            },
            ..shared.look.clone()
        };
        let options = Options {
            look: look.clone(),
            ..shared
        };
        let settings = volray_options::settings(&options).map_err(|e| self.refused(e))?;
        Ok((look, settings))
    }

    /// An option error of this overlay (its own or the volume's) as one
    /// line naming the overlay and its options as written.
    pub fn refused(&self, e: OptionError) -> Refused {
        Refused(format!(
            "--overlay {}: {}",
            self.spec,
            e.message(&OverlayNaming)
        ))
    }
}

/// The options of a remainder after ':', as (name, value) pairs: tokens
/// split at ','; `name=value` starts an option, a bare number continues
/// the value before (`range=0,100`), `labels` is a bare word. `None`
/// where the remainder does not read as options.
fn option_tokens(rest: &str) -> Option<Vec<(String, Option<String>)>> {
    let mut options: Vec<(String, Option<String>)> = Vec::new();
    for token in rest.split(',') {
        let token = token.trim();
        if let Some((name, value)) = token.split_once('=') {
            let word = !name.is_empty()
                && (name.chars()).all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
            if !word {
                return None;
            }
            options.push((name.to_string(), Some(value.to_string())));
        } else if token == "labels" || token == "hidden" {
            options.push((token.to_string(), None));
        } else if token.parse::<f64>().is_ok()
            && let Some((_, Some(value))) = options.last_mut()
        {
            value.push(',');
            value.push_str(token);
        } else {
            return None;
        }
    }
    Some(options)
}

/// How an overlay's options are written: `preset=`, `labels`; the shared
/// flags as flags.
pub struct OverlayNaming;

impl OverlayNaming {
    fn own(opt: Opt) -> bool {
        matches!(
            opt,
            Opt::Opacity | Opt::Tf | Opt::Preset | Opt::Colormap | Opt::Labels | Opt::Range
        )
    }
}

impl Naming for OverlayNaming {
    fn option(&self, opt: Opt) -> String {
        match opt {
            Opt::Labels => "labels".to_string(),
            opt if Self::own(opt) => format!("{}=", opt.name()),
            opt => format!("--{}", opt.name()),
        }
    }

    fn with_value(&self, opt: Opt, value: &str) -> String {
        if Self::own(opt) {
            format!("{}={value}", opt.name())
        } else {
            format!("--{} {value}", opt.name())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parsed(spec: &str) -> OverlaySpec {
        OverlaySpec::parse(spec).unwrap()
    }

    #[test]
    fn overlay_options_follow_the_last_colon_that_reads_as_options() {
        let o = parsed("seg.nii.gz:labels");
        assert_eq!((o.file.as_str(), o.labels), ("seg.nii.gz", true));
        let o = parsed("ct.nii:range=0,100,opacity=0,0.5,colormap=magma,frame=2");
        assert_eq!(o.file, "ct.nii");
        assert_eq!(o.range, Some((0.0, 100.0)));
        assert_eq!(o.opacity, Some((0.0, 0.5)));
        assert_eq!(o.colormap.as_deref(), Some("magma"));
        assert_eq!(o.frame, Some(2));
        // File specs with a ':' of their own stay whole.
        assert_eq!(parsed("file.h5:/dataset").file, "file.h5:/dataset");
        assert_eq!(parsed("file.nc:/var").file, "file.nc:/var");
        let o = parsed("file.h5:/group/data:labels,preset=mr");
        assert_eq!(o.file, "file.h5:/group/data");
        assert_eq!(o.preset.as_deref(), Some("mr"));
        assert_eq!(parsed("plain.nrrd").file, "plain.nrrd");
        let message = |spec: &str| OverlaySpec::parse(spec).unwrap_err().0;
        assert_eq!(
            message("seg.nii.gz:color=red"),
            format!("--overlay seg.nii.gz:color=red: unknown option \"color\" ({OVERLAY_OPTIONS})")
        );
        assert!(message("a.nii:range=5,1").contains("range=5,1"));
        assert!(message("a.nii:labels,labels").contains("twice"));
    }
}
