//! A viewer started from the volumes its front end read and checked
//! ([`Launch`]): the starting state checked against the viewer's bounds
//! and reproduced once (a state the page cannot show, or whose command
//! would be refused, stops the start rather than the first frame), the
//! page's first message made ([`Start::hello`]), and the [`Viewer`]
//! assembled, its volumes shared by the tabs. `volray view` starts here,
//! with one volume, a chunked file's levels, a scene or a time axis.

use crate::open::Opened;
use crate::{FigureContext, Refusal, Reproduce, Start, StateError, TimePoints, ViewState, Viewer};
use std::sync::Arc;
use volray_core::{NonFinite, RenderSettings, Volume};

/// What a viewer serves, read and checked by its front end.
pub struct Launch {
    /// The first volume's name, as given, and the volume as rendered
    /// (log10 of the data's when `log`; a chunked file's level read
    /// first, with `levels`).
    pub name: String,
    pub volume: Volume,
    pub log: bool,
    /// The starting state, and the settings it renders with.
    pub state: ViewState,
    pub settings: RenderSettings,
    /// A scene's other volumes: each one's name, volume and starting
    /// settings.
    pub others: Vec<(String, Volume, RenderSettings)>,
    /// A time axis served one time point at a time; not with `levels`.
    pub time: Option<TimePoints>,
    /// A chunked file served level by level.
    pub levels: Option<Opened>,
    /// Whether the page fits the frame to its window (no size given).
    pub fit: bool,
    /// How non-finite values are rendered, the brick caches' budget of
    /// each tab's renderer, the memory limit of the whole server.
    pub non_finite: NonFinite,
    pub cache_budget: usize,
    pub max_memory: u128,
    pub reproduce: Arc<dyn Reproduce>,
    pub pool: rayon::ThreadPool,
    /// The most tabs rendering at once.
    pub max_sessions: usize,
    pub figure: FigureContext,
}

/// A starting view that cannot be served.
#[derive(Debug, thiserror::Error)]
pub enum LaunchError {
    #[error("the starting view is beyond the viewer's bounds: {0}")]
    State(StateError),
    /// The starting state's command refused (`name`: the first volume).
    #[error("{name}: {refusal}")]
    Refused { name: String, refusal: Refusal },
}

impl Launch {
    /// The viewer, once the starting state is checked and reproduced.
    pub fn viewer(self) -> Result<Viewer, LaunchError> {
        self.state.check().map_err(LaunchError::State)?;
        (self.reproduce.reproduce(&self.state)).map_err(|refusal| LaunchError::Refused {
            name: self.name.clone(),
            refusal,
        })?;
        let others = (self.others.iter())
            .map(|(name, volume, settings)| (name.as_str(), volume, settings))
            .collect();
        let mut hello = Start {
            name: &self.name,
            volume: &self.volume,
            log: self.log,
            state: &self.state,
            settings: &self.settings,
            others,
            time: self.time.as_ref().map(|t| t.range),
        }
        .hello();
        if let Some(opened) = &self.levels {
            opened.pyramid.describe(&mut hello);
        }
        hello.fit = self.fit;
        let labels = self.volume.is_labels();
        Ok(Viewer {
            volume: Arc::new(self.volume),
            non_finite: self.non_finite,
            cache_budget: self.cache_budget,
            max_memory: self.max_memory,
            hello,
            reproduce: self.reproduce,
            pool: Arc::new(self.pool),
            max_sessions: self.max_sessions,
            levels: self.levels.map(|o| o.into_levels(labels)),
            others: (self.others.into_iter())
                .map(|(_, volume, _)| Arc::new(volume))
                .collect(),
            time: self.time,
            figure: self.figure,
        })
    }
}
