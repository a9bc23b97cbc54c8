//! A single-slot mailbox: the latest request replaces the one waiting, so
//! a renderer that falls behind skips to the newest view instead of
//! working through a queue. A "Save PNG" request has a slot of its own,
//! so that the view requests that follow it do not drop it.
//!
//! The sender never waits; the receiver waits for a request or for the
//! mailbox to close (the tab went away, the server is stopping).
//!
//! The mailbox also holds the stop flag of the frame being rendered: a
//! request for the slot whose frame is being rendered sets it (the frame
//! is superseded: its view is no longer the page's), and so does closing.
//! A view does not stop a save, nor a save a view: the file asked for is
//! still wanted while the view moves. Nor does a draft stop a draft: while
//! the view moves, each draft is finished and the newest waiting one
//! rendered next, so that a drag whose moves come faster than its drafts
//! render still shows frames (and the page learns their times to shrink
//! them); a draft does stop a full-size frame, and a full-size request a
//! draft. The renderer passes the flag to
//! volray-core, whose casters stop within a tile's work.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Condvar, Mutex, MutexGuard};

/// What a mailbox holds: at most one view request and one save request.
#[derive(Debug)]
struct Slots<T> {
    latest: Option<T>,
    save: Option<T>,
    probe: Option<T>,
    closed: bool,
    /// Requests replaced before they were taken.
    dropped: u64,
    /// The slot of the request taken last, until [`Mailbox::finished`].
    rendering: Option<Slot>,
    /// Whether the request taken last is a draft.
    rendering_draft: bool,
}

/// What the mailbox asks of a request.
pub trait Kind {
    /// A draft, which does not stop a draft being rendered.
    fn is_draft(&self) -> bool;
}

/// A single-slot mailbox of requests `T`.
#[derive(Debug)]
pub struct Mailbox<T> {
    slots: Mutex<Slots<T>>,
    ready: Condvar,
    /// Set when the request being rendered is superseded or the mailbox
    /// closes; cleared when the next request is taken.
    stop: AtomicBool,
}

/// Which slot a request goes to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Slot {
    /// The view: a newer request replaces a waiting one.
    Latest,
    /// A save: likewise, in its own slot.
    Save,
    /// A probe of a pixel: likewise; taken before the view (it is quick).
    Probe,
}

impl<T: Kind> Default for Mailbox<T> {
    fn default() -> Self {
        Mailbox {
            slots: Mutex::new(Slots {
                latest: None,
                save: None,
                probe: None,
                closed: false,
                dropped: 0,
                rendering: None,
                rendering_draft: false,
            }),
            ready: Condvar::new(),
            stop: AtomicBool::new(false),
        }
    }
}

impl<T: Kind> Mailbox<T> {
    fn lock(&self) -> MutexGuard<'_, Slots<T>> {
        // A panic elsewhere cannot leave the slots inconsistent.
        self.slots.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Puts `request` in its slot, replacing (dropping) what waits there,
    /// and stops the frame of that slot being rendered. A closed mailbox
    /// drops it.
    pub fn put(&self, slot: Slot, request: T) {
        let mut slots = self.lock();
        if slots.closed {
            return;
        }
        if slots.rendering == Some(slot) && !(slots.rendering_draft && request.is_draft()) {
            // Under the lock, so that `take` cannot clear it for the
            // request that supersedes the frame.
            self.stop.store(true, Ordering::Relaxed);
        }
        let place = match slot {
            Slot::Latest => &mut slots.latest,
            Slot::Save => &mut slots.save,
            Slot::Probe => &mut slots.probe,
        };
        if place.replace(request).is_some() {
            slots.dropped += 1;
        }
        drop(slots);
        self.ready.notify_one();
    }

    /// Waits for a request (a save first, then a probe) and takes it, clearing the stop
    /// flag for its frame; `None` once the mailbox is closed.
    pub fn take(&self) -> Option<T> {
        let mut slots = self.lock();
        slots.rendering = None;
        loop {
            if slots.closed {
                return None;
            }
            let taken = (slots.save.take().map(|save| (Slot::Save, save)))
                .or_else(|| slots.probe.take().map(|probe| (Slot::Probe, probe)))
                .or_else(|| slots.latest.take().map(|view| (Slot::Latest, view)));
            if let Some((slot, request)) = taken {
                slots.rendering = Some(slot);
                slots.rendering_draft = request.is_draft();
                self.stop.store(false, Ordering::Relaxed);
                return Some(request);
            }
            slots = self.ready.wait(slots).unwrap_or_else(|e| e.into_inner());
        }
    }

    /// Closes the mailbox: waiting requests are dropped and [`Self::take`]
    /// returns `None`.
    pub fn close(&self) {
        let mut slots = self.lock();
        slots.closed = true;
        slots.latest = None;
        slots.save = None;
        slots.probe = None;
        self.stop.store(true, Ordering::Relaxed);
        drop(slots);
        self.ready.notify_all();
    }

    /// The frame being rendered is done: requests put from now on no
    /// longer stop it (they wait for the next [`Self::take`]).
    pub fn finished(&self) {
        self.lock().rendering = None;
    }

    /// The stop flag of the request taken last, for the renderer.
    pub fn stop_flag(&self) -> &AtomicBool {
        &self.stop
    }

    /// Whether the request taken last was superseded or the mailbox closed.
    #[cfg(test)]
    pub fn stopped(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    /// How many requests were replaced before they were taken.
    pub fn dropped(&self) -> u64 {
        self.lock().dropped
    }

    /// How many requests wait (0, 1 or 2).
    #[cfg(test)]
    pub fn waiting(&self) -> usize {
        let slots = self.lock();
        usize::from(slots.latest.is_some())
            + usize::from(slots.save.is_some())
            + usize::from(slots.probe.is_some())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    impl Kind for u32 {
        fn is_draft(&self) -> bool {
            false
        }
    }

    impl Kind for i32 {
        fn is_draft(&self) -> bool {
            false
        }
    }

    /// "draft ..." is a draft.
    impl Kind for &str {
        fn is_draft(&self) -> bool {
            self.starts_with("draft")
        }
    }

    #[test]
    fn a_draft_does_not_stop_a_draft_but_a_full_frame_and_is_stopped_by_one() {
        let mailbox = Mailbox::default();
        mailbox.put(Slot::Latest, "draft 1");
        assert_eq!(mailbox.take(), Some("draft 1"));
        mailbox.put(Slot::Latest, "draft 2");
        assert!(!mailbox.stopped(), "a draft finishes while the next waits");
        mailbox.put(Slot::Latest, "draft 3");
        assert!(!mailbox.stopped());
        mailbox.put(Slot::Latest, "full 1");
        assert!(mailbox.stopped(), "the still supersedes the draft");
        assert_eq!(mailbox.take(), Some("full 1"));
        mailbox.put(Slot::Latest, "draft 4");
        assert!(mailbox.stopped(), "a moving view supersedes the still");
        assert_eq!(mailbox.dropped(), 2);
    }

    #[test]
    fn a_burst_leaves_only_the_latest() {
        let mailbox = Mailbox::default();
        for i in 0..1000 {
            mailbox.put(Slot::Latest, i);
        }
        assert_eq!(mailbox.waiting(), 1);
        assert_eq!(mailbox.dropped(), 999);
        assert_eq!(mailbox.take(), Some(999));
        assert_eq!(mailbox.waiting(), 0);
    }

    #[test]
    fn a_save_survives_the_views_after_it_and_goes_first() {
        let mailbox = Mailbox::default();
        mailbox.put(Slot::Latest, "view 1");
        mailbox.put(Slot::Save, "save");
        mailbox.put(Slot::Latest, "view 2");
        assert_eq!(mailbox.take(), Some("save"));
        assert_eq!(mailbox.take(), Some("view 2"));
        assert_eq!(mailbox.dropped(), 1);
    }

    #[test]
    fn closing_wakes_the_receiver_and_drops_what_waits() {
        let mailbox = Arc::new(Mailbox::<u32>::default());
        let receiver = {
            let mailbox = Arc::clone(&mailbox);
            std::thread::spawn(move || mailbox.take())
        };
        mailbox.close();
        assert_eq!(receiver.join().unwrap(), None);
        mailbox.put(Slot::Latest, 1);
        assert_eq!(mailbox.waiting(), 0);
        assert_eq!(mailbox.take(), None);
    }

    #[test]
    fn a_newer_request_stops_the_frame_of_its_slot_only() {
        let mailbox = Mailbox::default();
        mailbox.put(Slot::Latest, "view 1");
        assert_eq!(mailbox.take(), Some("view 1"));
        assert!(!mailbox.stopped());
        // A save does not stop the view being rendered; a newer view does.
        mailbox.put(Slot::Save, "save");
        assert!(!mailbox.stopped());
        mailbox.put(Slot::Latest, "view 2");
        assert!(mailbox.stopped());
        // The next request taken starts unstopped; a view does not stop
        // the save being rendered, a newer save does.
        assert_eq!(mailbox.take(), Some("save"));
        assert!(!mailbox.stopped());
        mailbox.put(Slot::Latest, "view 3");
        assert!(!mailbox.stopped());
        mailbox.put(Slot::Save, "save 2");
        assert!(mailbox.stopped());
        // Once the frame is finished, requests wait without stopping it.
        assert_eq!(mailbox.take(), Some("save 2"));
        mailbox.finished();
        mailbox.put(Slot::Save, "save 3");
        assert!(!mailbox.stopped());
        // Closing stops whatever is rendered.
        mailbox.close();
        assert!(mailbox.stopped());
    }

    #[test]
    fn a_waiting_receiver_gets_a_request_put_later() {
        let mailbox = Arc::new(Mailbox::default());
        let receiver = {
            let mailbox = Arc::clone(&mailbox);
            std::thread::spawn(move || mailbox.take())
        };
        mailbox.put(Slot::Latest, 7);
        assert_eq!(receiver.join().unwrap(), Some(7));
    }
}
