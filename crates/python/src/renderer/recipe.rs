//! A renderer's [`Recipe`]: the volume and its volume-level keywords,
//! prepared (again whenever the samples change) into a core renderer
//! within `max_memory` (volray-app's `memory`), and the settings of its
//! frames.

use super::*;

impl Recipe {
    /// The bytes to digest, where the samples can change under the
    /// renderer.
    pub(super) fn watched(&self, py: Python<'_>) -> PyResult<Option<ArrayBytes>> {
        match &self.source {
            Source::Volume(v) if v.get().frozen => Ok(None),
            Source::Volume(v) => ArrayBytes::new(v.get().array(py)?, None).map(Some),
            Source::Array { object, .. } => array::watched(object.bind(py)).map(Some),
        }
    }

    /// The digest of the samples as they are now (on `pool`, or the
    /// global pool; the GIL released while hashing); `None` if they are
    /// read-only.
    pub(crate) fn digest(
        &self,
        py: Python<'_>,
        pool: Option<&rayon::ThreadPool>,
    ) -> PyResult<Option<u64>> {
        let Some(watched) = self.watched(py)? else {
            return Ok(None);
        };
        Ok(Some(py.detach(|| match pool {
            Some(pool) => pool.install(|| watched.digest()),
            None => watched.digest(),
        })))
    }

    /// The volume prepared from its samples, whose digest is `digest`:
    /// value range, labels or histogram, non-finite values, the brick
    /// caches' budget for frames of `settings`. Samples read in place are
    /// checked against the digest after each frame (`ArrayBytes::verify`).
    pub(crate) fn prepare(
        &self,
        py: Python<'_>,
        digest: Option<u64>,
        settings: &RenderSettings,
    ) -> PyResult<Prepared> {
        let core = match &self.source {
            Source::Volume(v) => v.get().core_expecting(py, digest)?,
            Source::Array {
                object,
                order,
                spacing,
                origin,
            } => {
                let object = object.bind(py);
                let volume = Volume::from_array(object, *spacing, *origin, *order, false)?;
                // Checked after each frame only where the frame reads the
                // caller's memory; a copy is the renderer's alone.
                let kept = ArrayBytes::new(volume.array(py)?, None)?;
                let in_place = digest.is_some() && array::watched(object)?.same_bytes(&kept);
                volume.core_expecting(py, digest.filter(|_| in_place))?
            }
        };
        self.prepare_core(py, core, digest, settings)
    }

    /// [`Recipe::prepare`] of the samples `core`.
    pub(crate) fn prepare_core(
        &self,
        py: Python<'_>,
        mut core: CoreVolume,
        digest: Option<u64>,
        settings: &RenderSettings,
    ) -> PyResult<Prepared> {
        let name = &self.name;
        if let Some(s) = self.spacing {
            core = core
                .with_spacing(s.into())
                .map_err(|e| value_error(format!("spacing: {e}")))?;
        }
        if let Some(o) = self.origin {
            core = core
                .with_origin(o.into())
                .map_err(|e| value_error(format!("origin: {e}")))?;
        }
        // Axes in different units stretched for drawing, or as `scale=`
        // says (the command line's rule: volray-app's `display`).
        let stretch =
            volray_app::display::stretch(self.display.as_ref(), core.extent(), self.scale);
        if let Some(s) = stretch {
            core = volray_app::display::stretched(core, s.factors)
                .map_err(|e| value_error(format!("scale: {e}")))?;
        }
        if self.log {
            core = py
                .detach(|| core.to_log10())
                .map_err(|e| value_error(format!("log=True: {name}: {e}")))?;
        }
        let (found_labels, histogram) = if self.labels {
            let found = volray_options::volume_labels(&core, name).map_err(option_error)?;
            (Some(found), None)
        } else {
            (None, py.detach(|| auto::robust_histogram_of(&core)))
        };
        let core = if self.labels { core.as_labels() } else { core };
        let nonfinite = self.nonfinite;
        let inner = py
            .detach(|| CoreRenderer::owning(core, nonfinite))
            .map_err(|e| render_error(e, &volray_options::CameraOptions::default(), name))?;
        let inner = {
            let budget = cache_budget(&inner, settings, nonfinite, self.max_memory);
            inner.with_cache_budget(budget)
        };
        Ok(Prepared {
            inner,
            known: Known {
                labels: found_labels,
                histogram,
            },
            digest,
        })
    }
}

impl Recipe {
    /// The recipe of `volume` (an array or a `Volume`) with the
    /// volume-level keywords of `k` (but `level`).
    pub(crate) fn build(volume: &Bound<'_, PyAny>, k: &Keywords<'_>) -> PyResult<Self> {
        let order = match k.take::<String>("order", "'zyx' or 'xyz'")? {
            Some(o) => Order::parse(&o)?,
            None => Order::Xyz,
        };
        let spacing = k.take::<[f64; 3]>("spacing", "three numbers (dx, dy, dz)")?;
        let scale = k.take::<[f64; 3]>("scale", "three positive numbers (x, y, z)")?;
        if let Some(s) = scale
            && !s.iter().all(|v| v.is_finite() && *v > 0.0)
        {
            return Err(value_error(format!(
                "scale: {s:?}: every factor must be positive"
            )));
        }
        let origin = k.take::<[f64; 3]>("origin", "three numbers (x, y, z)")?;
        let labels_given = k.take::<bool>("labels", "True or False")?;
        let (source, spacing, origin, vol_labels, name, nan_is_empty) =
            match volume.cast::<Volume>() {
                Ok(v) => {
                    if k.get("order").is_some() {
                        return Err(value_error(
                            "order applies to numpy arrays; a volray.Volume's axes are fixed",
                        ));
                    }
                    let vol = v.get();
                    let (labels, name, nan) = (vol.labels, vol.name.clone(), vol.nan_is_empty());
                    let source = Source::Volume(v.clone().unbind());
                    (source, spacing, origin, labels, name, nan)
                }
                Err(_) => {
                    let source = Source::Array {
                        object: volume.clone().unbind(),
                        order,
                        spacing,
                        origin,
                    };
                    (source, None, None, false, "volume".to_string(), false)
                }
            };
        let labels = labels_given.unwrap_or(vol_labels);
        let log = k.take::<bool>("log", "True or False")?.unwrap_or(false);
        if labels && log {
            return Err(value_error(
                "labels=True conflicts with log=True: a label volume's values are names, not quantities",
            ));
        }
        let requested = keywords::nonfinite(k)?;
        let nonfinite = if nan_is_empty {
            NonFinite::Transparent
        } else {
            requested
        };
        let max_memory = k
            .take::<u64>("max_memory", "a number of bytes")?
            .unwrap_or_else(volray_io::default_max_memory);
        let window = match &source {
            Source::Volume(v) => v.get().display_window(),
            Source::Array { .. } => None,
        };
        let label_colours = match &source {
            Source::Volume(v) => v.get().label_colours(),
            Source::Array { .. } => Vec::new(),
        };
        // What the file says of its axes' units and its modality.
        let display = match &source {
            Source::Volume(v) => v.get().file.as_ref().map(|(_, info)| volray_io::FileInfo {
                axis_units: info.axis_units.clone(),
                modality: info.modality.clone(),
                ..volray_io::FileInfo::default()
            }),
            Source::Array { .. } => None,
        };
        Ok(Recipe {
            source,
            spacing,
            origin,
            scale,
            display,
            labels,
            log,
            nonfinite,
            max_memory,
            name,
            window,
            label_colours,
        })
    }

    /// The options and settings of a frame of this volume with the frame
    /// keywords of `k` (its file's display window the default range).
    pub(crate) fn settings_of(&self, k: &Keywords<'_>) -> PyResult<(Options, RenderSettings)> {
        let options = keywords::options(k, self.look())?;
        let mut settings =
            volray_options::settings(&options).map_err(|e| settings_error(e, &options.camera))?;
        volray_options::file_window(&options.look, &mut settings.transfer_function, self.window);
        Ok((options, settings))
    }

    /// What the annotations take from the volume: its file's units and
    /// axes, and whether it is rendered as log10.
    pub(crate) fn facts(&self, py: Python<'_>) -> figure::Facts {
        match &self.source {
            Source::Volume(v) => figure::Facts::of(v.bind(py).get().file.as_ref(), self.log),
            Source::Array { .. } => figure::Facts::of(None, self.log),
        }
    }

    /// The chunked file a lazy volume is read from, if it is one.
    pub(crate) fn lazy(&self) -> Option<&LazyFile> {
        match &self.source {
            Source::Volume(v) => v.get().lazy.as_ref(),
            Source::Array { .. } => None,
        }
    }

    /// Whether a spacing or origin was given with the volume (or `log`):
    /// what applies to a level read whole, not yet to a pyramid's levels.
    pub(crate) fn reshaped(&self) -> bool {
        self.spacing.is_some() || self.origin.is_some() || self.log
    }

    /// `scale=` as given, if it was.
    pub(crate) fn scale(&self) -> Option<[f64; 3]> {
        self.scale
    }

    /// The file's display window (an OME-Zarr `omero` window), if any.
    pub(crate) fn window(&self) -> Option<(f64, f64)> {
        self.window
    }

    /// The look options the recipe fixes (labels, log).
    pub(crate) fn look(&self) -> LookOptions {
        LookOptions {
            labels: self.labels,
            log: self.log,
            ..LookOptions::default()
        }
    }

    /// Puts into `settings` what `options` leave to the volume, as
    /// volray-options' from_volume does, from what `prepared` found
    /// once: the labels' transfer function, or the automatic one.
    pub(crate) fn leave_to_volume(
        &self,
        known: &Known,
        options: &Options,
        settings: &mut RenderSettings,
    ) -> PyResult<()> {
        match (&known.labels, &known.histogram) {
            (Some(found), _) => {
                // The colours the file gives its labels, unless given.
                let look =
                    volray_app::look::with_file_colours(&options.look, self.label_colours.clone());
                volray_options::label_transfer_function(
                    &look,
                    &mut settings.transfer_function,
                    found,
                    &self.name,
                )
                .map_err(option_error)
            }
            (None, Some(histogram)) if options.look.auto_tf() => {
                // A CT in Hounsfield units: the CT look (volray-app's `look`).
                let modality = self.display.as_ref().and_then(|i| i.modality.as_deref());
                let range = Some((histogram.histogram.min, histogram.histogram.max));
                if let Some((tf, _)) = volray_app::look::ct_look(&options.look, modality, range) {
                    settings.transfer_function = tf;
                    return Ok(());
                }
                volray_options::apply_auto(
                    &options.look,
                    &mut settings.transfer_function,
                    histogram,
                );
                Ok(())
            }
            _ => Ok(()),
        }
    }

    /// Refuses a frame that may take more than `max_memory` even with no
    /// brick cache (the command line's rule: volray-app's `memory`).
    pub(crate) fn check_memory(
        &self,
        inner: &CoreRenderer<'_>,
        settings: &RenderSettings,
    ) -> PyResult<()> {
        let (volume, name) = (inner.volume(), &self.name);
        let refused = volray_app::memory::cache_budget(
            volume,
            name,
            settings,
            self.nonfinite,
            budget(self.max_memory),
        );
        if let Err(AppError::OverBudget(over)) = refused {
            let [nx, ny, nz] = over.dims;
            return Err(value_error(format!(
                "{name}: rendering {nx}x{ny}x{nz} voxels at {}x{} pixels may take up to {}, more than max_memory {} (raise it, or use a smaller grid)",
                over.size.0,
                over.size.1,
                format_bytes(over.need),
                format_bytes(over.limit),
            )));
        }
        Ok(())
    }
}
