//! A BigDataViewer `dataset.xml` (SpimData, as Fiji's BigDataViewer,
//! BigStitcher and npy2bdv write it), read into the few facts a volume
//! needs: where the HDF5 file is, each view setup's id, name, size and
//! voxel size, the time points, and each view's registration.
//!
//! - `SequenceDescription/ImageLoader` with `format="bdv.hdf5"` and its
//!   `hdf5` path (`type="relative"`: to the XML's folder and `BasePath`);
//!   other loaders (N5, Zarr, OME-Zarr through BDV) are refused by name.
//! - `ViewSetups/ViewSetup`: `id`, `name`, `size` (x y z), `voxelSize`
//!   (`unit`, `size` x y z).
//! - `Timepoints`: `type="range"` (`first`, `last`) or `"pattern"`
//!   (`integerpattern`, "0-9" or "0, 2, 4") or `"list"` (`id`s).
//! - `ViewRegistrations/ViewRegistration` (`timepoint`, `setup`), each a
//!   list of `ViewTransform`s (`affine`: 12 numbers, rows of a 3×4
//!   matrix), composed as SpimData composes them: the first listed is
//!   applied last, `A = T1 · T2 · … · Tn`.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use quick_xml::events::{BytesStart, Event};

use crate::shared::xml::{attributes, local};

/// One view setup (a channel, tile or angle: each is read as a channel).
#[derive(Debug, Clone)]
pub(super) struct Setup {
    pub id: usize,
    pub name: String,
    /// The physical size of a voxel and its unit, if given.
    pub voxel: Option<([f64; 3], String)>,
}

/// What the XML says.
#[derive(Debug)]
pub(super) struct SpimData {
    pub hdf5: PathBuf,
    pub setups: Vec<Setup>,
    pub timepoints: Vec<usize>,
    /// The composed registration of each (time point, setup): rows of a
    /// 3×4 affine.
    pub registrations: HashMap<(usize, usize), [[f64; 4]; 3]>,
}

/// The XML's largest size read: a dataset of thousands of views is a few
/// megabytes.
const MAX_XML: u64 = 64 << 20;

/// An element: its name, attributes, text and children.
#[derive(Debug, Default)]
struct Node {
    name: String,
    attrs: Vec<(String, String)>,
    text: String,
    children: Vec<Node>,
}

impl Node {
    fn child(&self, name: &str) -> Option<&Node> {
        self.children.iter().find(|c| c.name == name)
    }
    fn all<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a Node> + 'a {
        self.children.iter().filter(move |c| c.name == name)
    }
    fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }
    fn text_of(&self, name: &str) -> Option<&str> {
        self.child(name).map(|c| c.text.trim())
    }
}

/// Whether the first bytes of a file are a SpimData XML.
pub(crate) fn sniff(head: &str) -> bool {
    head.trim_start().starts_with("<?xml") && head.contains("<SpimData")
}

/// Reads the SpimData XML at `path`; errors in words.
pub(super) fn read(path: &Path) -> Result<SpimData, String> {
    let len = std::fs::metadata(path).map_err(|e| e.to_string())?.len();
    if len > MAX_XML {
        return Err(format!("{len} bytes of XML, more than {MAX_XML} read"));
    }
    let text = std::fs::read_to_string(path).map_err(|e| format!("not UTF-8 XML text: {e}"))?;
    let root = tree(&text)?;
    if root.name != "SpimData" {
        return Err(format!("root element <{}>, not <SpimData>", root.name));
    }
    let dir = path.parent().unwrap_or(Path::new("."));
    let base = match root.child("BasePath") {
        Some(b) if b.attr("type") == Some("absolute") => PathBuf::from(b.text.trim()),
        Some(b) => dir.join(b.text.trim()),
        None => dir.to_path_buf(),
    };
    let seq = root
        .child("SequenceDescription")
        .ok_or("no <SequenceDescription>")?;
    let loader = seq.child("ImageLoader").ok_or("no <ImageLoader>")?;
    let format = loader.attr("format").unwrap_or("");
    if format != "bdv.hdf5" {
        return Err(format!(
            "ImageLoader format \"{format}\" is not read: volray reads BigDataViewer HDF5 (bdv.hdf5)"
        ));
    }
    let h5 = loader
        .child("hdf5")
        .ok_or("the ImageLoader names no <hdf5> file")?;
    let hdf5 = match h5.attr("type") {
        Some("absolute") => PathBuf::from(h5.text.trim()),
        _ => base.join(h5.text.trim()),
    };
    let views = seq.child("ViewSetups").ok_or("no <ViewSetups>")?;
    let mut setups = Vec::new();
    for s in views.all("ViewSetup") {
        let id = number::<usize>(s.text_of("id"), "ViewSetup id")?;
        let voxel = match s.child("voxelSize") {
            Some(v) => {
                let size = numbers(v.text_of("size"), "voxelSize size")?;
                let size: [f64; 3] = size
                    .try_into()
                    .map_err(|_| "voxelSize size is not three numbers")?;
                if size.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
                    return Err(format!("voxelSize {size:?} is not positive"));
                }
                Some((size, v.text_of("unit").unwrap_or("").to_string()))
            }
            None => None,
        };
        let name = s.text_of("name").unwrap_or("").to_string();
        setups.push(Setup { id, name, voxel });
    }
    if setups.is_empty() {
        return Err("no <ViewSetup>".into());
    }
    setups.sort_by_key(|s| s.id);
    let timepoints = timepoints(seq.child("Timepoints"))?;
    let mut registrations = HashMap::new();
    if let Some(regs) = root.child("ViewRegistrations") {
        for r in regs.all("ViewRegistration") {
            let t = number::<usize>(r.attr("timepoint"), "ViewRegistration timepoint")?;
            let s = number::<usize>(r.attr("setup"), "ViewRegistration setup")?;
            let mut a = [
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
            ];
            for vt in r.all("ViewTransform") {
                let m = numbers(vt.text_of("affine"), "ViewTransform affine")?;
                if m.len() != 12 || m.iter().any(|x| !x.is_finite()) {
                    return Err("a ViewTransform affine is not 12 finite numbers".into());
                }
                a = compose(
                    a,
                    [
                        [m[0], m[1], m[2], m[3]],
                        [m[4], m[5], m[6], m[7]],
                        [m[8], m[9], m[10], m[11]],
                    ],
                );
            }
            registrations.insert((t, s), a);
        }
    }
    Ok(SpimData {
        hdf5,
        setups,
        timepoints,
        registrations,
    })
}

/// `a · b` for affines of rows of 3×4.
fn compose(a: [[f64; 4]; 3], b: [[f64; 4]; 3]) -> [[f64; 4]; 3] {
    let mut out = [[0.0; 4]; 3];
    for r in 0..3 {
        for c in 0..4 {
            out[r][c] =
                (0..3).map(|k| a[r][k] * b[k][c]).sum::<f64>() + if c == 3 { a[r][3] } else { 0.0 };
        }
    }
    out
}

/// The time points of `<Timepoints>` (one, 0, where there is none).
fn timepoints(node: Option<&Node>) -> Result<Vec<usize>, String> {
    let Some(node) = node else { return Ok(vec![0]) };
    let out: Vec<usize> = match node.attr("type") {
        Some("range") => {
            let first = number::<usize>(node.text_of("first"), "Timepoints first")?;
            let last = number::<usize>(node.text_of("last"), "Timepoints last")?;
            if last < first || last - first > 1_000_000 {
                return Err(format!("Timepoints {first} to {last}"));
            }
            (first..=last).collect()
        }
        Some("pattern") => {
            let text = node.text_of("integerpattern").unwrap_or("");
            let mut v = Vec::new();
            for part in text.split(',') {
                let part = part.trim();
                match part.split_once('-') {
                    Some((a, b)) => {
                        let (a, b) = (
                            number::<usize>(Some(a), "Timepoints")?,
                            number(Some(b), "Timepoints")?,
                        );
                        if b < a || b - a > 1_000_000 {
                            return Err(format!("Timepoints pattern {part}"));
                        }
                        v.extend(a..=b);
                    }
                    None => v.push(number(Some(part), "Timepoints")?),
                }
            }
            v
        }
        Some("list") => node
            .all("Timepoint")
            .map(|t| number::<usize>(t.text_of("id"), "Timepoint id"))
            .collect::<Result<_, _>>()?,
        other => return Err(format!("Timepoints type {other:?} is not read")),
    };
    if out.is_empty() {
        return Err("no time point".into());
    }
    Ok(out)
}

fn number<T: std::str::FromStr>(text: Option<&str>, what: &str) -> Result<T, String> {
    let text = text.ok_or_else(|| format!("no {what}"))?.trim();
    text.parse()
        .map_err(|_| format!("{what} \"{text}\" is not a number"))
}

fn numbers(text: Option<&str>, what: &str) -> Result<Vec<f64>, String> {
    let text = text.ok_or_else(|| format!("no {what}"))?;
    text.split_whitespace()
        .map(|w| {
            w.parse::<f64>()
                .map_err(|_| format!("{what} \"{w}\" is not a number"))
        })
        .collect()
}

/// The document's root element, with its descendants (at most
/// [`MAX_DEPTH`] deep).
fn tree(xml: &str) -> Result<Node, String> {
    const MAX_DEPTH: usize = 64;
    let mut reader = quick_xml::Reader::from_str(xml);
    let mut stack: Vec<Node> = vec![Node::default()];
    loop {
        let event = reader
            .read_event()
            .map_err(|e| format!("XML error near byte {}: {e}", reader.error_position()))?;
        match event {
            Event::Start(ref e) => {
                if stack.len() > MAX_DEPTH {
                    return Err(format!("elements nested more than {MAX_DEPTH} deep"));
                }
                stack.push(node(e)?);
            }
            Event::Empty(ref e) => {
                let n = node(e)?;
                stack.last_mut().expect("the document").children.push(n);
            }
            Event::Text(t) => {
                let text = t.xml_content(quick_xml::XmlVersion::Implicit1_0);
                stack.last_mut().expect("the document").text.push_str(&text);
            }
            Event::End(_) => {
                let n = stack.pop().expect("an open element");
                let parent = stack.last_mut().ok_or("an end tag without a start")?;
                parent.children.push(n);
            }
            Event::Eof => break,
            _ => {}
        }
    }
    let document = stack.pop().ok_or("no document")?;
    if !stack.is_empty() {
        return Err("elements left open at the end".into());
    }
    document
        .children
        .into_iter()
        .next()
        .ok_or_else(|| "no root element".into())
}

fn node(e: &BytesStart) -> Result<Node, String> {
    Ok(Node {
        name: local(e),
        attrs: attributes(e)?,
        ..Node::default()
    })
}
