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
//!
//! A socket slows the renderer when the page reads slowly; the caller's
//! connection (the notebook's comm) takes whatever it is given. So the
//! page acknowledges each frame ([`Tab::ack`]) and at most
//! [`MAX_IN_FLIGHT`] frames are handed over unacknowledged: the next
//! waits in [`Tab::next`], and the renderer behind it, while the page's
//! newer requests replace each other in the mailbox. A frame's message
//! bytes stay reserved in the ledger until it is acknowledged (or the
//! tab closes).

use crate::ledger::Reservation;
use crate::mailbox::Mailbox;
use crate::protocol::{self, Request};
use crate::session::{self, Outgoing, Shared, SpawnError};
use crate::state::ViewState;
use crate::watch::Watch;
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use tokio::sync::mpsc;

/// The most frames a page holds unacknowledged.
pub const MAX_IN_FLIGHT: usize = 2;

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
    /// The frames handed over and not acknowledged, oldest first: their
    /// messages' bytes held in the ledger.
    in_flight: Mutex<VecDeque<Reservation>>,
    /// Notified when a frame is acknowledged or the tab closes.
    room: Condvar,
    closed: AtomicBool,
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
            in_flight: Mutex::new(VecDeque::new()),
            room: Condvar::new(),
            closed: AtomicBool::new(false),
        })
    }

    /// Asks `watch` for the volume before each frame of every tab opened
    /// from now on (`watch.rs`).
    pub fn watch(&mut self, watch: Arc<dyn Watch>) {
        self.shared.watch = Some(watch);
    }

    /// The bytes the ledger holds now: the volume, the tabs' renderers,
    /// the frames rendering and those not yet acknowledged.
    pub fn held(&self) -> u128 {
        self.shared.ledger.held()
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
        protocol::file(&self.mailbox, text).map_err(|e| e.to_json())
    }

    /// The next message for the page, waiting for it: the hello first,
    /// then frames and errors as the renderer makes them, a frame only
    /// once fewer than [`MAX_IN_FLIGHT`] are unacknowledged; `None` once
    /// the tab is closed (and its renderer has ended, unless it closed
    /// while a frame waited for room). Not to be called from within an
    /// async runtime.
    pub fn next(&self) -> Option<Message> {
        if let Some(hello) = lock(&self.hello).take() {
            return Some(Message::Text(hello));
        }
        // A frame's bytes stay reserved until it is acknowledged.
        match lock(&self.out).blocking_recv()? {
            Outgoing::Frame(bytes, reserved) => {
                let mut in_flight = lock(&self.in_flight);
                while in_flight.len() >= MAX_IN_FLIGHT && !self.is_closed() {
                    in_flight = (self.room.wait(in_flight)).unwrap_or_else(|e| e.into_inner());
                }
                if self.is_closed() {
                    return None;
                }
                in_flight.push_back(reserved);
                Some(Message::Frame(bytes))
            }
            Outgoing::Text(text) => Some(Message::Text(text)),
        }
    }

    /// The page has the oldest frame handed over: its bytes are given
    /// back, and the next frame may go. Nothing where none is in flight.
    pub fn ack(&self) {
        lock(&self.in_flight).pop_front();
        self.room.notify_all();
    }

    /// The frames handed over and not acknowledged.
    pub fn in_flight(&self) -> usize {
        lock(&self.in_flight).len()
    }

    /// Stops the frame being rendered, if any, and ends the renderer:
    /// [`Tab::next`] then returns `None`. The frames in flight are let go
    /// of.
    pub fn close(&self) {
        self.closed.store(true, Ordering::SeqCst);
        self.mailbox.close();
        lock(&self.in_flight).clear();
        self.room.notify_all();
    }

    fn is_closed(&self) -> bool {
        self.closed.load(Ordering::SeqCst)
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
