//! A single-slot mailbox: the latest request replaces the one waiting, so
//! a renderer that falls behind skips to the newest view instead of
//! working through a queue. A "Save PNG" request has a slot of its own,
//! so that the view requests that follow it do not drop it.
//!
//! The sender never waits; the receiver waits for a request or for the
//! mailbox to close (the tab went away, the server is stopping).

use std::sync::{Condvar, Mutex, MutexGuard};

/// What a mailbox holds: at most one view request and one save request.
#[derive(Debug)]
struct Slots<T> {
    latest: Option<T>,
    save: Option<T>,
    closed: bool,
    /// Requests replaced before they were taken.
    dropped: u64,
}

/// A single-slot mailbox of requests `T`.
#[derive(Debug)]
pub struct Mailbox<T> {
    slots: Mutex<Slots<T>>,
    ready: Condvar,
}

/// Which slot a request goes to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Slot {
    /// The view: a newer request replaces a waiting one.
    Latest,
    /// A save: likewise, in its own slot.
    Save,
}

impl<T> Default for Mailbox<T> {
    fn default() -> Self {
        Mailbox {
            slots: Mutex::new(Slots {
                latest: None,
                save: None,
                closed: false,
                dropped: 0,
            }),
            ready: Condvar::new(),
        }
    }
}

impl<T> Mailbox<T> {
    fn lock(&self) -> MutexGuard<'_, Slots<T>> {
        // A panic elsewhere cannot leave the slots inconsistent.
        self.slots.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Puts `request` in its slot, replacing (dropping) what waits there.
    /// A closed mailbox drops it.
    pub fn put(&self, slot: Slot, request: T) {
        let mut slots = self.lock();
        if slots.closed {
            return;
        }
        let place = match slot {
            Slot::Latest => &mut slots.latest,
            Slot::Save => &mut slots.save,
        };
        if place.replace(request).is_some() {
            slots.dropped += 1;
        }
        drop(slots);
        self.ready.notify_one();
    }

    /// Waits for a request (a save first) and takes it; `None` once the
    /// mailbox is closed.
    pub fn take(&self) -> Option<T> {
        let mut slots = self.lock();
        loop {
            if slots.closed {
                return None;
            }
            if let Some(request) = slots.save.take().or_else(|| slots.latest.take()) {
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
        drop(slots);
        self.ready.notify_all();
    }

    /// How many requests were replaced before they were taken.
    pub fn dropped(&self) -> u64 {
        self.lock().dropped
    }

    /// How many requests wait (0, 1 or 2).
    #[cfg(test)]
    pub fn waiting(&self) -> usize {
        let slots = self.lock();
        usize::from(slots.latest.is_some()) + usize::from(slots.save.is_some())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

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
