//! A lazy volume's frames (`Road::Lazy`): each frame's level, then that
//! level read whole or rendered in pieces as volray-lazy's plan says
//! (see `renderer.rs`'s opening comment), and its value range.

use super::*;

impl Renderer {
    /// A frame of a lazy volume: its level, then the level whole or in
    /// pieces, as its plan says.
    pub(super) fn lazy_frame(
        &self,
        py: Python<'_>,
        lazy: &LazyRoad,
        options: &Options,
        mut settings: RenderSettings,
        pool: Option<rayon::ThreadPool>,
        what: &Annotations,
    ) -> PyResult<Frame> {
        let level = self.level_for(lazy, &settings, &options.camera)?;
        let pool = pool.as_ref();
        let name = &self.recipe.name;
        let settings_ref = &mut settings;
        let next = py.detach(|| -> PyResult<(Next, Option<Image>)> {
            let mut state = lazy.state.lock().unwrap_or_else(|e| e.into_inner());
            self.settle(lazy, &mut state, level, settings_ref)?;
            state.settings = Some(settings_ref.clone());
            if let Way::Whole { prepared, .. } = &state.way {
                return Ok((Next::Whole(Arc::clone(prepared)), None));
            }
            let Way::Pieces {
                streamed, found, ..
            } = &mut state.way
            else {
                unreachable!("settled above")
            };
            figure::refuse_pieces(what, name)?;
            lazy.stop.store(false, Ordering::SeqCst);
            let settings = &mut *settings_ref;
            let (rendered, interrupt) = interruptible(pool, &lazy.stop, |report| {
                found
                    .apply(streamed, &options.look, settings, name)
                    .and_then(|()| {
                        let request = FrameRequest::new(&*settings).reporting(report);
                        (streamed.render(request.stopped_by(&lazy.stop)))
                            .map(Rendered::image_and_times)
                            .map_err(LookError::Stream)
                    })
            });
            let rendered = rendered.map_err(|panic| {
                // What the pieces knew may be half updated: start afresh.
                state.way = Way::None;
                internal_error(name, &panic)
            });
            if let Some(e) = interrupt {
                return Err(e);
            }
            let (image, _times) = rendered?.map_err(|e| match e {
                LookError::Stream(e) => stream_error(e, &options.camera, name),
                LookError::Refused(e) => option_error(e),
            })?;
            Ok((Next::Pieces, Some(image)))
        })?;
        match next {
            (Next::Whole(prepared), _) => {
                self.render_prepared(py, &prepared, options, settings, pool, what)
            }
            (Next::Pieces, image) => Ok(Frame {
                image: image.expect("a frame in pieces returns its image"),
            }),
        }
    }

    /// The level a frame of `settings` needs: `level="auto"`'s choice
    /// for the view, or the level asked for.
    pub(super) fn level_for(
        &self,
        lazy: &LazyRoad,
        settings: &RenderSettings,
        camera: &CameraOptions,
    ) -> PyResult<usize> {
        match lazy.choice {
            LevelChoice::Index(n) => Ok(n),
            LevelChoice::Auto => lazy_file(lazy)
                .chunked
                .auto_level(settings)
                .map_err(|e| render_error(RenderError::from(e), camera, &self.recipe.name)),
        }
    }

    /// Makes `state` ready for a frame of `settings` at `level`: the level
    /// open, and read whole (prepared) or set to be rendered in pieces,
    /// as volray-lazy's plan says for `max_memory`. What the last frame
    /// kept is kept where the plan is the same. Called detached from
    /// Python, the state locked.
    pub(super) fn settle(
        &self,
        lazy: &LazyRoad,
        state: &mut LazyState,
        level: usize,
        settings: &RenderSettings,
    ) -> PyResult<()> {
        let file = lazy_file(lazy);
        let name = &self.recipe.name;
        if state.chunked.as_ref().map(Chunked::level) != Some(level) {
            state.way = Way::None;
            state.chunked = None;
            let chunked = file.chunked.open_level(level).map_err(io_error)?;
            state.chunked = Some(chunked.stoppable(Arc::clone(&lazy.stop)));
        }
        let Some(chunked) = &state.chunked else {
            unreachable!("opened above")
        };
        let own = file.chunked.level();
        let overridden =
            self.recipe.spacing.is_some() || self.recipe.origin.is_some() || file.spacing_given;
        let refuse_override = |how: &str| {
            value_error(format!(
                "{name}: spacing and origin given apply to level {own} read whole, not to level {level} {how}: leave them out (the file's own are used)"
            ))
        };
        let (mode, max_memory) = (self.recipe.nonfinite, self.recipe.max_memory);
        // volray-app's plan of the level, as `volray render` plans it: the
        // pieces of this level kept from the last frame, where it is
        // pieces again (with log=True, no second pass over the level).
        let frames = Frames {
            settings,
            non_finite: mode,
            log: self.recipe.log,
            labels: self.recipe.labels,
            extra: 0,
        };
        let kept = matches!(state.way, Way::Pieces { level: l, .. } if l == level);
        let planned = plan::plan_level(chunked, name, &frames, max_memory, kept);
        let Some(plan) = planned.map_err(app_error)? else {
            return Ok(());
        };
        match plan {
            Plan::Whole { level, .. } => {
                if overridden && level != own {
                    return Err(refuse_override("read whole"));
                }
                // Kept while its caches' budget fits this frame (see
                // `cache_budget`).
                let kept = match &state.way {
                    Way::Whole { level: l, prepared } if *l == level => {
                        prepared.fits(settings, mode, max_memory)
                    }
                    _ => false,
                };
                if !kept {
                    // The last level's samples go before the next is read.
                    state.way = Way::None;
                    let prepared =
                        Python::attach(|py| self.prepare_level(py, lazy, file, chunked, settings))?;
                    state.way = Way::Whole {
                        level,
                        prepared: Arc::new(prepared),
                    };
                }
            }
            Plan::Pieces {
                level, streamed, ..
            } => {
                if overridden {
                    return Err(refuse_override("in pieces"));
                }
                if !matches!(state.way, Way::Pieces { level: l, .. } if l == level) {
                    // Stretched for drawing as the command line's pieces.
                    let scale = self.recipe.scale;
                    let (streamed, _) =
                        plan::stretched_pieces(chunked, *streamed, &frames, max_memory, scale);
                    state.way = Way::Pieces {
                        level,
                        streamed: Box::new(streamed.with_labels(self.recipe.labels)),
                        found: Found::default(),
                    };
                }
            }
        }
        Ok(())
    }

    /// The level `chunked` read whole and prepared for frames of
    /// `settings`: the volume's own samples where `data` read them
    /// already, else read from the file (volray-app's reading, as
    /// `volray render` reads a level that fits).
    pub(super) fn prepare_level(
        &self,
        py: Python<'_>,
        lazy: &LazyRoad,
        file: &LazyFile,
        chunked: &Chunked,
        settings: &RenderSettings,
    ) -> PyResult<Prepared> {
        let volume = lazy.volume.get();
        let level = chunked.level();
        if level == file.chunked.level() && volume.loaded(py).is_some() {
            return (self.recipe).prepare_core(py, volume.core(py)?, None, settings);
        }
        let max_memory = self.recipe.max_memory;
        let mut core = py
            .detach(|| file.read_level(level, max_memory))
            .map_err(app_error)?;
        if volume.labels {
            core = core.as_labels();
        }
        self.recipe.prepare_core(py, core, None, settings)
    }

    /// A lazy volume's value range: of the level of the last frame; before
    /// the first (or after one that failed), of the level asked for (the
    /// volume's own with `level="auto"`, which needs a view). Read whole,
    /// or found piece by piece (every piece read once).
    pub(super) fn lazy_value_range(&self, py: Python<'_>, lazy: &LazyRoad) -> PyResult<(f32, f32)> {
        let (options, default, _) = self.settings_of(&Keywords::new(None, &[], "value_range")?)?;
        let name = &self.recipe.name;
        py.detach(|| {
            let mut state = lazy.state.lock().unwrap_or_else(|e| e.into_inner());
            let settings = match (&state.way, state.settings.clone()) {
                (Way::Whole { .. } | Way::Pieces { .. }, Some(settings)) => settings,
                _ => {
                    // A small frame: the range does not depend on it, and
                    // the pieces need fit no picture.
                    let settings = RenderSettings {
                        width: 16,
                        height: 16,
                        ..default
                    };
                    let level = match lazy.choice {
                        LevelChoice::Index(n) => n,
                        LevelChoice::Auto => lazy_file(lazy).chunked.level(),
                    };
                    self.settle(lazy, &mut state, level, &settings)?;
                    state.settings = Some(settings.clone());
                    settings
                }
            };
            match &mut state.way {
                Way::None => unreachable!("settled by a frame before, or above"),
                Way::Whole { prepared, .. } => Ok(prepared.inner.value_range()),
                Way::Pieces {
                    streamed, found, ..
                } => {
                    let histogram = found
                        .histogram(streamed, &settings)
                        .map_err(|e| stream_error(e, &options.camera, name))?;
                    Ok(histogram.map_or((0.0, 0.0), |h| (h.min, h.max)))
                }
            }
        })
    }
}
