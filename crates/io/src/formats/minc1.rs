//! MINC1 (`.mnc` whose magic is `CDF`): NetCDF-3 files in libminc's
//! layout, read on the NetCDF-3 layer (`formats/netcdf/`) with MINC2's
//! semantics (`formats/minc_common.rs`: [`spatial_split`], [`geometry`],
//! [`Scaling`]), matching nibabel's `Minc1File`.
//!
//! - The image is the variable `image`; its dimensions name its axes,
//!   slowest first (`zspace, yspace, xspace` in any order, after an
//!   optional leading `time`, whose volumes are frames).
//! - Each dimension has a variable of its name (a scalar) whose
//!   attributes give `step`, `start`, `direction_cosines` and `units`, as
//!   MINC2's dimension datasets do.
//! - The stored type is NetCDF's, signed, reinterpreted as unsigned where
//!   the image's `signtype` is `"unsigned"` (MINC's default for bytes);
//!   integer images are scaled per slice by the `image-min` and
//!   `image-max` variables over `valid_range`, as in MINC2.

use std::path::Path;

use crate::error::IoError;
use crate::formats::minc_common::{Scaling, geometry, scale_slices, spatial_split, valid_range_of};
use crate::formats::netcdf::header::{
    self, Header, NcType, check_in_file, read_values, small_values,
};
use crate::shared::cf::Value;
use crate::shared::geometry::grid_to_volume;
use crate::shared::limits::check_frame_dims;
use crate::{FileInfo, Loaded, ReadOptions, VolumeFormat};

/// Whether a NetCDF-3 header is MINC1's: a variable `image` with three
/// dimensions named `*space`.
pub(crate) fn is_minc1(header: &Header) -> bool {
    header.vars.iter().any(|v| {
        v.name == "image"
            && v.dims
                .iter()
                .filter(|&&d| header.dims[d].name.ends_with("space"))
                .count()
                == 3
    })
}

/// Reads the MINC1 file at `path`.
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<Loaded, IoError> {
    let (file, header) = header::open(path)?;
    read_parsed(path, opts, file, header)
}

/// Reads a MINC1 file already parsed as NetCDF-3.
pub(crate) fn read_parsed(
    path: &Path,
    opts: &ReadOptions,
    mut file: std::fs::File,
    header: Header,
) -> Result<Loaded, IoError> {
    let fail = |reason: String| IoError::invalid(path, format!("MINC1: {reason}"));
    let image = header
        .vars
        .iter()
        .find(|v| v.name == "image")
        .ok_or_else(|| fail("no variable \"image\": not a MINC1 file".into()))?;
    let what = |reason: String| fail(format!("variable image: {reason}"));
    let order: Vec<String> = image
        .dims
        .iter()
        .map(|&d| header.dims[d].name.clone())
        .collect();
    let shape: Vec<usize> = header
        .shape(image)
        .iter()
        .map(|&n| usize::try_from(n).unwrap_or(usize::MAX))
        .collect();
    let (frames, spatial) = spatial_split(&order, &shape).map_err(what)?;
    let frame = opts.frame.unwrap_or(0);
    if frame >= frames {
        return Err(IoError::frame_out_of_range(
            path,
            frame,
            format!(
                "the MINC1 image holds {frames} volume(s) along \"{}\", numbered from 0",
                order[0]
            ),
        ));
    }
    let total = check_frame_dims(
        path,
        &format!("image shape {shape:?}"),
        &shape,
        frames,
        4,
        opts.max_memory,
    )?;
    let voxels = total / frames;
    let attr = |name: &str| image.attrs.iter().find(|(n, _)| n == name).map(|(_, v)| v);

    // The stored type, with MINC's signtype (default: unsigned bytes,
    // signed others).
    let unsigned = match attr("signtype") {
        Some(v) if is_text(Some(v), "unsigned") => true,
        Some(v) if is_text(Some(v), "signed__") => false,
        Some(other) => {
            return Err(what(format!(
                "signtype {} is neither \"signed__\" nor \"unsigned\"",
                other.shown()
            )));
        }
        None => image.ty == NcType::Byte,
    };
    let (type_name, range, wrap) = match (image.ty, unsigned) {
        (NcType::Byte, false) => ("int8", Some((-128.0, 127.0)), 0.0),
        (NcType::Byte, true) => ("uint8", Some((0.0, 255.0)), 256.0),
        (NcType::Short, false) => ("int16", Some((-32768.0, 32767.0)), 0.0),
        (NcType::Short, true) => ("uint16", Some((0.0, 65535.0)), 65536.0),
        (NcType::Int, false) => ("int32", Some((-2147483648.0, 2147483647.0)), 0.0),
        (NcType::Int, true) => ("uint32", Some((0.0, 4294967295.0)), 4294967296.0),
        (NcType::Float, _) => ("float32", None, 0.0),
        (NcType::Double, _) => ("float64", None, 0.0),
        (other, _) => {
            return Err(what(format!(
                "type {} is not a MINC1 image type",
                other.name()
            )));
        }
    };

    let mut info = FileInfo::new(format!("{type_name} (big-endian)"));
    info.frames = frames;
    info.frame = frame;
    info.header = vec![
        ("format".into(), "MINC1 (NetCDF-3)".into()),
        ("image".into(), format!("({})", order.join(", "))),
        ("shape".into(), format!("{shape:?}")),
        ("type".into(), type_name.into()),
    ];
    info.header.extend(
        image
            .attrs
            .iter()
            .map(|(k, v)| (format!("@{k}"), v.shown())),
    );

    let attrs_of = |name: &str| -> Vec<(String, Value)> {
        header
            .vars
            .iter()
            .find(|v| v.name == name)
            .map(|v| v.attrs.clone())
            .unwrap_or_default()
    };
    let names = &order[spatial..];
    let (steps, origin) =
        geometry(names, &attrs_of, "the dimension variables", &mut info).map_err(fail)?;

    let scaling = match range {
        None => {
            info.notes
                .push("float image: real values as stored (no image-min/image-max scaling)".into());
            None
        }
        Some(type_range) => {
            let min_var = header.vars.iter().find(|v| v.name == "image-min");
            let max_var = header.vars.iter().find(|v| v.name == "image-max");
            match (min_var, max_var) {
                (Some(min_var), Some(max_var)) => {
                    let given = attr("valid_range").map(|v| match v {
                        Value::Numbers(n) => Some(n.clone()),
                        Value::Text(_) => None,
                    });
                    let (lo, hi) = valid_range_of(given.clone(), type_range).map_err(what)?;
                    let dims_of = |v: &header::Var| -> Vec<String> {
                        v.dims
                            .iter()
                            .map(|&d| header.dims[d].name.clone())
                            .collect()
                    };
                    let (min_order, max_order) = (dims_of(min_var), dims_of(max_var));
                    scale_slices(&min_order, &max_order, &order, &shape).map_err(what)?;
                    let limit = total as u64;
                    let min = small_values(path, &mut file, &header, min_var, None, limit)?;
                    let max = small_values(path, &mut file, &header, max_var, None, limit)?;
                    Some(
                        Scaling::new(
                            (lo, hi),
                            min,
                            max,
                            &shape,
                            &min_order,
                            given.is_some(),
                            &mut info,
                        )
                        .map_err(what)?,
                    )
                }
                _ => {
                    info.notes.push(
                        "no image-min/image-max variables: the stored values are read as they are"
                            .into(),
                    );
                    None
                }
            }
        }
    };
    if frames > 1 {
        info.notes.push(format!(
            "volume {frame} of {frames} read (first axis: {})",
            order[0]
        ));
    }

    // The frame must lie in the file before it is allocated.
    let base = frame * voxels;
    check_in_file(path, &header, image, (base + voxels - 1) as u64)?;
    let mut data = vec![0f32; voxels];
    read_values(
        path,
        &mut file,
        &header,
        image,
        base as u64,
        voxels,
        &mut |i, v| {
            let v = if v < 0.0 { v + wrap } else { v };
            data[i] = match &scaling {
                Some(s) => s.real(base + i, v),
                None => v,
            } as f32;
        },
    )?;
    let n = &shape[spatial..];
    let dims = [n[2], n[1], n[0]];
    let steps = [steps[2], steps[1], steps[0]];
    let volume = grid_to_volume(path, dims, data, steps, origin, &mut info)?;
    Ok(Loaded {
        volume,
        format: VolumeFormat::Minc,
        info,
    })
}

/// Whether `value` is the text `want` (MINC's fixed-width words).
fn is_text(value: Option<&Value>, want: &str) -> bool {
    matches!(value, Some(Value::Text(t)) if t.trim_end_matches(['\0', ' ']) == want)
}
