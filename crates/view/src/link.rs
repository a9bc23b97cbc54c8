//! The viewer without a server: [`Host`] holds what the server's routes
//! would share (the volume, its bytes in the ledger, the page's first
//! message), and each [`Tab`] is one page's renderer, whose messages the
//! caller carries both ways. The Python module's Jupyter widget carries
//! them over the notebook's own connection (the kernel's comm), so that
//! the viewer needs no port, no token and no proxy: the notebook's
//! server already authenticates that connection.
//!
//! A tab works as a WebSocket's does in `server.rs`: [`Tab::receive`]
//! files the page's requests in the tab's single-slot mailbox, its
//! thread renders the latest, and [`Tab::next`] hands back each message
//! for the page, the first being the [`Host::hello`].

use crate::ledger::Reservation;
use crate::mailbox::Mailbox;
use crate::protocol::Request;
use crate::server;
use crate::session::{self, Outgoing, Shared, SpawnError};
use crate::state::ViewState;
use std::sync::{Arc, Mutex};
use tokio::sync::mpsc;

/// A viewer whose tabs' messages the caller carries ([`crate::Viewer::host`]).
pub struct Host {
    /// The page's first message, the same for every tab.
    pub(crate) hello: String,
    pub(crate) shared: Shared,
    /// The volume's bytes in the ledger, for as long as the host lives.
    pub(crate) volume: Reservation,
}

/// A message for a page: JSON text, or a frame (`protocol.rs`'s binary
/// message: header and image).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Message {
    Text(String),
    Frame(Vec<u8>),
}

/// One page's renderer. Closed (its frame stopped, its thread ended, its
/// renderer and reservations freed) by [`Tab::close`] or when dropped.
pub struct Tab {
    mailbox: Arc<Mailbox<Request>>,
    /// The renderer's messages, the hello first; `None` once read.
    out: Mutex<mpsc::Receiver<Outgoing>>,
    hello: Mutex<Option<String>>,
}

impl Host {
    /// The page's first message (`protocol::Hello`), as JSON.
    pub fn hello(&self) -> &str {
        &self.hello
    }

    /// A new tab: its renderer thread started, its hello waiting in
    /// [`Tab::next`]. Refused beyond the most tabs at once or where its
    /// renderer does not fit the memory limit beside the others.
    pub fn open(&self) -> Result<Tab, SpawnError> {
        let mailbox = Arc::new(Mailbox::default());
        let (out_tx, out_rx) = mpsc::channel::<Outgoing>(1);
        session::spawn(&self.shared, Arc::clone(&mailbox), out_tx)?;
        Ok(Tab {
            mailbox,
            out: Mutex::new(out_rx),
            hello: Mutex::new(Some(self.hello.clone())),
        })
    }

    /// The bytes held for the volume.
    pub fn volume_bytes(&self) -> u128 {
        self.volume.bytes()
    }
}

impl Tab {
    /// Files a message from the page: `Ok` with the requested state where
    /// it asks for a view ("draft" or "full"), `Ok(None)` for a probe or
    /// a save, `Err` with the JSON error message for the page where it is
    /// refused (malformed, out of bounds).
    pub fn receive(&self, text: &str) -> Result<Option<ViewState>, String> {
        server::file(&self.mailbox, text).map_err(|e| e.to_json())
    }

    /// The next message for the page, waiting for it: the hello first,
    /// then frames and errors as the renderer makes them; `None` once
    /// the tab is closed and its renderer has ended. Not to be called
    /// from within an async runtime.
    pub fn next(&self) -> Option<Message> {
        if let Some(hello) = lock(&self.hello).take() {
            return Some(Message::Text(hello));
        }
        // A frame's bytes stay reserved until it is handed over.
        match lock(&self.out).blocking_recv()? {
            Outgoing::Frame(bytes, _reserved) => Some(Message::Frame(bytes)),
            Outgoing::Text(text) => Some(Message::Text(text)),
        }
    }

    /// Stops the frame being rendered, if any, and ends the renderer:
    /// [`Tab::next`] then returns `None` once the renderer is gone.
    pub fn close(&self) {
        self.mailbox.close();
    }
}

impl Drop for Tab {
    fn drop(&mut self) {
        self.mailbox.close();
    }
}

fn lock<T>(mutex: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    mutex.lock().unwrap_or_else(|e| e.into_inner())
}
