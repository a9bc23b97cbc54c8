//! OME-TIFF: the OME-XML a first page's `ImageDescription` holds (as
//! tifffile writes it with `ome=True`, Bio-Formats and OMERO too), read
//! for the first `<Image>`'s `<Pixels>`:
//! - `SizeZ`, `SizeC`, `SizeT` and `DimensionOrder` (`XYZCT`, `XYCZT`, ...:
//!   after X and Y, the plane axes fastest first) say which page holds
//!   slice z of channel c at time point t; the volume is the Z pages of
//!   one (c, t), and the (c, t) pairs are frames numbered `t·SizeC + c`
//!   (as ImageJ hyperstacks number them);
//! - `PhysicalSizeX`, `Y`, `Z` with `PhysicalSize{X,Y,Z}Unit` (the schema's
//!   default: µm) give the spacing, all converted to the finest of their
//!   units when they differ (`shared/units.rs`, as every reader does); a
//!   size in `pixel` or `reference frame` is no length, and leaves that
//!   axis at spacing 1; another unit is refused (the schema's
//!   `UnitsLength` holds lengths only).
//!
//! `<TiffData>` elements that map planes to pages other than one after
//! another from page 0 (`FirstZ`/`FirstC`/`FirstT`, several blocks, other
//! files) are not followed: the file is refused, naming the element. Stage
//! positions (`<Plane PositionX=...>`) are not read: the origin is 0.
//! The OME-XML is parsed with `quick-xml`, the XML crate volray already
//! uses for VTK's XML files.

use std::path::Path;

use quick_xml::events::Event;

use crate::shared::xml::{attributes, local};
use volray_core::glam::DVec3;

use super::imagej::Shape;
use crate::FileInfo;
use crate::error::IoError;
use crate::shared::units::{AxisUnit, metres, one_length_unit};

/// What the OME-XML says of the first image.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Ome {
    pub(super) shape: Shape,
    /// The plane axes fastest first: a permutation of `b"ZCT"`.
    order: [u8; 3],
    pub(super) dimension_order: String,
    /// Physical sizes of x, y, z with their units, as written.
    sizes: [Option<(f64, String)>; 3],
    /// `<Image>` elements in the document.
    pub(super) images: usize,
}

/// Whether an `ImageDescription` is OME-XML.
pub(super) fn is_ome(description: &str) -> bool {
    let head = description.trim_start();
    (head.starts_with("<?xml") || head.starts_with("<OME")) && description.contains("<OME")
}

impl Ome {
    /// Parses the OME-XML `xml` of the TIFF at `path`.
    pub(super) fn parse(path: &Path, xml: &str) -> Result<Ome, IoError> {
        let fail = |reason: String| IoError::invalid(path, format!("OME-XML: {reason}"));
        let mut reader = quick_xml::Reader::from_str(xml);
        let mut pixels: Option<Vec<(String, String)>> = None;
        let mut images = 0usize;
        let mut in_first_pixels = false;
        let mut tiff_data: Vec<Vec<(String, String)>> = Vec::new();
        loop {
            let event = reader.read_event().map_err(|e| {
                fail(format!(
                    "XML error near byte {}: {e}",
                    reader.error_position()
                ))
            })?;
            match event {
                Event::Start(ref e) | Event::Empty(ref e) => {
                    let empty = matches!(event, Event::Empty(_));
                    match local(e).as_str() {
                        "Image" => images += 1,
                        "Pixels" if pixels.is_none() => {
                            pixels = Some(attributes(e).map_err(&fail)?);
                            in_first_pixels = !empty;
                        }
                        "TiffData" if in_first_pixels => {
                            tiff_data.push(attributes(e).map_err(&fail)?)
                        }
                        _ => {}
                    }
                }
                Event::End(ref e) if e.local_name().as_ref() == "Pixels" => {
                    in_first_pixels = false;
                }
                Event::Eof => break,
                _ => {}
            }
        }
        let pixels = pixels.ok_or_else(|| fail("no <Pixels> element".into()))?;
        let get = |key: &str| pixels.iter().find(|(k, _)| k == key).map(|(_, v)| v.trim());
        let count = |key: &str| -> Result<usize, IoError> {
            match get(key) {
                None => Ok(1),
                Some(v) => match v.parse::<usize>() {
                    Ok(n) if n >= 1 => Ok(n),
                    _ => Err(fail(format!(
                        "Pixels {key}=\"{v}\" is not a positive count"
                    ))),
                },
            }
        };
        let shape = Shape {
            slices: count("SizeZ")?,
            channels: count("SizeC")?,
            times: count("SizeT")?,
        };
        let dimension_order = get("DimensionOrder").unwrap_or("XYZCT").to_string();
        let order = plane_order(&dimension_order).ok_or_else(|| {
            fail(format!(
                "Pixels DimensionOrder=\"{dimension_order}\" is not XY followed by Z, C and T in some order"
            ))
        })?;
        for td in &tiff_data {
            let attr = |k: &str| td.iter().find(|(n, _)| n == k).map(|(_, v)| v.as_str());
            let moved = ["FirstZ", "FirstC", "FirstT", "IFD"]
                .iter()
                .find(|k| attr(k).is_some_and(|v| v.trim() != "0"));
            if tiff_data.len() > 1 || moved.is_some() {
                return Err(fail(format!(
                    "<TiffData{}> maps planes to pages in a way volray does not follow ({} TiffData elements): only planes stored one per page from page 0 in DimensionOrder are read",
                    td.iter()
                        .map(|(k, v)| format!(" {k}=\"{v}\""))
                        .collect::<String>(),
                    tiff_data.len()
                )));
            }
        }
        let mut sizes: [Option<(f64, String)>; 3] = [None, None, None];
        for (a, axis) in ["X", "Y", "Z"].into_iter().enumerate() {
            let key = format!("PhysicalSize{axis}");
            if let Some(v) = get(&key) {
                let size = v
                    .parse::<f64>()
                    .ok()
                    .filter(|s| s.is_finite() && *s > 0.0)
                    .ok_or_else(|| {
                        fail(format!("Pixels {key}=\"{v}\" is not a positive length"))
                    })?;
                let unit = get(&format!("{key}Unit")).unwrap_or("µm").to_string();
                sizes[a] = Some((size, unit));
            }
        }
        Ok(Ome {
            shape,
            order,
            dimension_order,
            sizes,
            images,
        })
    }

    /// Planes of the first image (`usize::MAX` for more than can be
    /// counted, which no file has pages for).
    pub(super) fn planes(&self) -> usize {
        self.shape
            .slices
            .checked_mul(self.shape.channels)
            .and_then(|n| n.checked_mul(self.shape.times))
            .unwrap_or(usize::MAX)
    }

    /// The page (counted among full-resolution pages) of slice `z` of
    /// channel `c` at time point `t`.
    pub(super) fn page(&self, z: usize, c: usize, t: usize) -> usize {
        let (mut page, mut stride) = (0, 1);
        for axis in self.order {
            let (i, n) = match axis {
                b'Z' => (z, self.shape.slices),
                b'C' => (c, self.shape.channels),
                _ => (t, self.shape.times),
            };
            page += i * stride;
            stride *= n;
        }
        page
    }

    /// The spacing and its unit (see the module docs), with a note.
    pub(super) fn geometry(&self, path: &Path, info: &mut FileInfo) -> Result<DVec3, IoError> {
        info.header.push((
            "OME Pixels".into(),
            format!(
                "DimensionOrder {}, SizeZ {}, SizeC {}, SizeT {}",
                self.dimension_order, self.shape.slices, self.shape.channels, self.shape.times
            ),
        ));
        let mut spacing = DVec3::ONE;
        // A size in pixels or reference frames is no length: that axis
        // keeps spacing 1. The others go through `shared/units.rs`: every
        // length to the finest of their units, others kept apart.
        let given: Vec<(usize, f64, &str)> = self
            .sizes
            .iter()
            .enumerate()
            .filter_map(|(a, s)| s.as_ref().map(|(v, u)| (a, *v, u.as_str())))
            .filter(|(_, _, u)| !matches!(*u, "pixel" | "reference frame"))
            .collect();
        if given.is_empty() {
            info.notes.push(format!(
                "OME-XML gives no physical size in a length unit: spacing 1, 1, 1 (DimensionOrder {})",
                self.dimension_order
            ));
            return Ok(spacing);
        }
        // The schema's UnitsLength allows lengths only: another unit is a
        // malformed file, not an axis to keep apart.
        if let Some(&(a, _, u)) = given.iter().find(|(_, _, u)| metres(u).is_none()) {
            return Err(IoError::invalid(
                path,
                format!(
                    "OME-XML: PhysicalSize{}Unit \"{u}\" is not a length unit volray knows",
                    ["X", "Y", "Z"][a]
                ),
            ));
        }
        let names = ["x", "y", "z"];
        let axes: Vec<AxisUnit> = given
            .iter()
            .map(|&(a, _, u)| AxisUnit {
                name: names[a],
                unit: Some(u),
            })
            .collect();
        let one = one_length_unit(&axes);
        for (&(a, v, _), f) in given.iter().zip(&one.factors) {
            spacing[a] = v * f;
        }
        let written: Vec<String> = self
            .sizes
            .iter()
            .zip(["X", "Y", "Z"])
            .filter_map(|(s, a)| s.as_ref().map(|(v, u)| format!("PhysicalSize{a} {v} {u}")))
            .collect();
        info.notes.push(format!(
            "spacing {}, {}, {}{} from OME-XML ({}); DimensionOrder {}",
            spacing.x,
            spacing.y,
            spacing.z,
            one.length_unit
                .as_ref()
                .map(|u| format!(" {u}"))
                .unwrap_or_default(),
            written.join(", "),
            self.dimension_order
        ));
        info.notes.extend(one.notes);
        // Every axis in one length unit: the volume's (an axis in pixels
        // leaves it without one, as the spacing then mixes units).
        info.length_unit = one.length_unit.filter(|_| given.len() == 3);
        Ok(spacing)
    }
}

/// The plane axes of an OME `DimensionOrder`, fastest first.
fn plane_order(order: &str) -> Option<[u8; 3]> {
    let b = order.as_bytes();
    if b.len() != 5 || &b[..2] != b"XY" {
        return None;
    }
    let planes = [b[2], b[3], b[4]];
    let mut sorted = planes;
    sorted.sort_unstable();
    (sorted == *b"CTZ").then_some(planes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dimension_order_puts_planes_fastest_first() {
        let xml = r#"<?xml version="1.0"?><OME><Image><Pixels DimensionOrder="XYZCT" SizeX="5" SizeY="4" SizeZ="3" SizeC="2" SizeT="2"><TiffData IFD="0" PlaneCount="12"/></Pixels></Image></OME>"#;
        let ome = Ome::parse(Path::new("a.ome.tif"), xml).unwrap();
        assert_eq!(ome.page(2, 1, 1), 2 + 3 * (1 + 2));
        let ome = Ome::parse(Path::new("a"), &xml.replace("XYZCT", "XYCZT")).unwrap();
        assert_eq!(ome.page(2, 1, 1), 1 + 2 * (2 + 3));
        let err = Ome::parse(Path::new("a"), &xml.replace("XYZCT", "XYZZT")).unwrap_err();
        assert!(
            err.to_string().contains("DimensionOrder=\"XYZZT\""),
            "{err}"
        );
        let err = Ome::parse(Path::new("a"), &xml.replace("IFD=\"0\"", "IFD=\"3\"")).unwrap_err();
        assert!(err.to_string().contains("IFD=\"3\""), "{err}");
        let huge = xml.replace(
            "SizeZ=\"3\" SizeC=\"2\" SizeT=\"2\"",
            &format!("SizeZ=\"{0}\" SizeC=\"{0}\" SizeT=\"{0}\"", u64::MAX),
        );
        assert_eq!(
            Ome::parse(Path::new("a"), &huge).unwrap().planes(),
            usize::MAX
        );
    }

    #[test]
    fn physical_sizes_in_several_units_become_one() {
        let xml = r#"<OME><Image><Pixels DimensionOrder="XYZCT" SizeZ="3" PhysicalSizeX="500" PhysicalSizeXUnit="nm" PhysicalSizeY="0.25" PhysicalSizeZ="0.002" PhysicalSizeZUnit="mm"/></Image></OME>"#;
        let ome = Ome::parse(Path::new("a"), xml).unwrap();
        let mut info = FileInfo::default();
        let s = ome.geometry(Path::new("a"), &mut info).unwrap();
        // The finest unit, nm: 500 nm, 0.25 µm = 250 nm, 0.002 mm = 2000 nm.
        assert_eq!(s, DVec3::new(500.0, 250.0, 2000.0));
        assert_eq!(info.length_unit.as_deref(), Some("nm"));
        assert!(
            info.notes.contains(
                &"x in nm, y in µm, z in mm: spacing in nm (y × 1000, z × 1000000)".to_string()
            ),
            "{:?}",
            info.notes
        );
    }
}
