//! What MINC1 (`minc1.rs`, on the NetCDF-3 layer) and MINC2 (`minc.rs`,
//! on the HDF5 layer) read alike, whichever layer gives the attributes:
//! which dimensions are spatial ([`spatial_split`]), the world geometry
//! of the dimensions' `step`, `start` and `direction_cosines`
//! ([`geometry`], nibabel's affine), and the map from stored to real
//! values of an integer image ([`Scaling`], nibabel's `_normalize`).

use volray_core::glam::DVec3;

use crate::FileInfo;
use crate::shared::cf::Value;
use crate::shared::units::{AxisUnit, one_length_unit};

/// Where the spatial dimensions of an image of dimensions `order` and
/// `shape` begin, and how many frames the dimension before them holds:
/// the last three are xspace, yspace and zspace in some order; a fourth,
/// leading, (time) holds frames.
pub(crate) fn spatial_split(order: &[String], shape: &[usize]) -> Result<(usize, usize), String> {
    let (frames, spatial) = match (shape, order) {
        ([_, _, _], [_, _, _]) => (1, 0),
        ([t, _, _, _], [first, ..]) if !first.ends_with("space") => (*t, 1),
        _ => {
            return Err(format!(
                "dimorder \"{}\" over shape {shape:?}: volray reads three spatial dimensions (xspace, yspace, zspace), after an optional leading one such as time",
                order.join(",")
            ));
        }
    };
    if let Some(bad) = order[spatial..].iter().find(|n| !n.ends_with("space")) {
        return Err(format!(
            "dimension \"{bad}\" is not spatial: volray reads xspace, yspace and zspace (after an optional leading time)"
        ));
    }
    Ok((frames, spatial))
}

/// The step vector of each spatial axis (in file order, slowest first)
/// and the world position of index 0, from the dimension datasets.
pub(crate) fn geometry(
    names: &[String],
    attrs_of: &dyn Fn(&str) -> Vec<(String, Value)>,
    source: &str,
    info: &mut FileInfo,
) -> Result<([DVec3; 3], DVec3), String> {
    let mut steps = [DVec3::ZERO; 3];
    let mut starts = [DVec3::ZERO; 3];
    let mut units: Vec<Option<String>> = Vec::new();
    let mut described = Vec::new();
    for (a, name) in names.iter().enumerate() {
        let default = match name.as_str() {
            "xspace" => DVec3::X,
            "yspace" => DVec3::Y,
            "zspace" => DVec3::Z,
            other => {
                return Err(format!(
                    "dimension \"{other}\": volray knows xspace, yspace and zspace"
                ));
            }
        };
        let attrs = attrs_of(name);
        let attr = |key: &str| attrs.iter().find(|(n, _)| n == key).map(|(_, v)| v);
        let numbers = |v: &Value| match v {
            Value::Numbers(n) => Some(n.clone()),
            Value::Text(_) => None,
        };
        let text = |v: &Value| match v {
            Value::Text(t) => Some(t.trim_end_matches(['\0', ' ']).to_string()),
            Value::Numbers(_) => None,
        };
        let number = |key: &str, default: f64| -> Result<f64, String> {
            match attr(key).map(numbers) {
                None => Ok(default),
                Some(Some(v)) if v.len() == 1 && v[0].is_finite() => Ok(v[0]),
                Some(_) => Err(format!(
                    "dimension {name}: attribute \"{key}\" is not one finite number"
                )),
            }
        };
        let step = number("step", 1.0)?;
        let start = number("start", 0.0)?;
        let cosines = match attr("direction_cosines").map(numbers) {
            None => default,
            Some(Some(v)) if v.len() == 3 && v.iter().all(|c| c.is_finite()) => {
                DVec3::new(v[0], v[1], v[2])
            }
            Some(_) => {
                return Err(format!(
                    "dimension {name}: attribute \"direction_cosines\" is not three finite numbers"
                ));
            }
        };
        if let Some(spacing) = attr("spacing").and_then(text)
            && spacing.starts_with("irregular")
        {
            return Err(format!(
                "dimension {name} is irregularly spaced: volray reads regular grids"
            ));
        }
        units.push(attr("units").and_then(text));
        steps[a] = cosines * step;
        starts[a] = cosines * start;
        described.push(format!(
            "{name} step {step} start {start} cosines ({}, {}, {})",
            cosines.x, cosines.y, cosines.z
        ));
    }
    info.notes.push(format!(
        "geometry from {source}: {}; world = Σ cosines · (start + step · index), nibabel's affine",
        described.join("; ")
    ));
    // Each dimension's `units` to the finest length unit (units.rs).
    let axes: Vec<AxisUnit> = names
        .iter()
        .zip(&units)
        .map(|(name, unit)| AxisUnit {
            name,
            unit: unit.as_deref(),
        })
        .collect();
    let one = one_length_unit(&axes);
    let mut origin = DVec3::ZERO;
    for (a, f) in one.factors.iter().enumerate() {
        steps[a] *= *f;
        origin += starts[a] * *f;
    }
    info.notes.extend(one.notes);
    info.length_unit = one.length_unit;
    Ok((steps, origin))
}

/// The map from stored to real values of an integer image, MINC1's and
/// MINC2's (nibabel's `_normalize`).
pub(crate) struct Scaling {
    /// Stored values are clipped to `[lo, hi]`, the valid range.
    lo: f64,
    hi: f64,
    /// image-min and image-max, one per slice of the first axes.
    min: Vec<f64>,
    max: Vec<f64>,
    /// Samples per value of `min` and `max`.
    per: usize,
}

impl Scaling {
    /// The scaling from valid range `[lo, hi]` onto image-min and
    /// image-max (`min`, `max`, one per slice of the image's first
    /// dimensions `min_order`); `valid_given`: whether the range is the
    /// file's `valid_range` rather than the type's.
    pub(crate) fn new(
        (lo, hi): (f64, f64),
        min: Vec<f64>,
        max: Vec<f64>,
        shape: &[usize],
        min_order: &[String],
        valid_given: bool,
        info: &mut FileInfo,
    ) -> Result<Scaling, String> {
        let k = min_order.len();
        let slices: usize = shape[..k].iter().product();
        if min.len() != slices || max.len() != slices {
            return Err(format!(
                "image-min/image-max hold {} and {} values for {slices} slices",
                min.len(),
                max.len()
            ));
        }
        let per = shape[k..].iter().product();
        info.notes.push(format!(
            "real values: stored values clipped to [{lo}, {hi}] ({}) mapped onto [image-min, image-max] {}",
            if valid_given { "valid_range" } else { "the type's range" },
            if k == 0 {
                format!("[{}, {}]", min[0], max[0])
            } else {
                format!("per slice of {}", min_order.join(","))
            }
        ));
        Ok(Scaling {
            lo,
            hi,
            min,
            max,
            per,
        })
    }

    /// The real value of stored value `v` at C-order index `at`.
    pub(crate) fn real(&self, at: usize, v: f64) -> f64 {
        let s = at / self.per;
        let (min, max) = (self.min[s], self.max[s]);
        let slope = (max - min) / (self.hi - self.lo);
        v.clamp(self.lo, self.hi) * slope + (min - self.lo * slope)
    }
}

/// The valid range: the image's `valid_range` attribute (`given`: absent,
/// or its numbers if numeric), else its integer type's range, within
/// which it must lie (nibabel's `_get_valid_range`).
pub(crate) fn valid_range_of(
    given: Option<Option<Vec<f64>>>,
    (type_lo, type_hi): (f64, f64),
) -> Result<(f64, f64), String> {
    let (lo, hi) = match given {
        None => (type_lo, type_hi),
        Some(Some(v)) if v.len() == 2 && v[0] < v[1] => (v[0], v[1]),
        Some(_) => return Err("attribute \"valid_range\" is not two increasing numbers".into()),
    };
    if lo < type_lo || hi > type_hi {
        return Err(format!(
            "valid_range [{lo}, {hi}] is outside the stored type's range [{type_lo}, {type_hi}]"
        ));
    }
    Ok((lo, hi))
}

/// Checks that image-min and image-max lie over the same first one or two
/// dimensions of the image (`order`, of `shape`); returns how many
/// values each holds, one per slice.
pub(crate) fn scale_slices(
    min_order: &[String],
    max_order: &[String],
    order: &[String],
    shape: &[usize],
) -> Result<usize, String> {
    if min_order != max_order {
        return Err("image-min and image-max have different dimensions".into());
    }
    let k = min_order.len();
    if k > 2 || k > order.len() || min_order != &order[..k] {
        return Err(format!(
            "image-min/image-max over \"{}\": volray reads scaling over the image's first one or two dimensions",
            min_order.join(",")
        ));
    }
    Ok(shape[..k].iter().product())
}
