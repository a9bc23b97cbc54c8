//! How ranks talk: the four operations compositing and agreeing need, over
//! MPI in a real run (module `mpi`, feature `mpi`) or over channels
//! between threads of one process ([`Local`], for tests and for trying
//! the algorithms without a cluster).

use std::sync::Mutex;
use std::sync::mpsc::{Receiver, Sender, channel};
use thiserror::Error;

/// A rank could not be reached.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
#[error("rank {rank}: {what}")]
pub struct TransportError {
    pub rank: usize,
    pub what: String,
}

/// Point-to-point byte messages among `size` ranks, in order per pair.
pub trait Transport {
    /// This rank, `0..size`.
    fn rank(&self) -> usize;
    /// The number of ranks.
    fn size(&self) -> usize;
    /// Sends `bytes` to rank `to` (may wait until `to` receives).
    fn send(&self, to: usize, bytes: &[u8]) -> Result<(), TransportError>;
    /// Receives the next message from rank `from`.
    fn receive(&self, from: usize) -> Result<Vec<u8>, TransportError>;
    /// Sends `bytes` to `partner` and receives `partner`'s message, both
    /// at once (the two call it together).
    fn exchange(&self, partner: usize, bytes: &[u8]) -> Result<Vec<u8>, TransportError>;

    /// Every rank's `bytes`, in rank order, on every rank: gathered on
    /// rank 0 and sent back out.
    fn all_gather(&self, bytes: &[u8]) -> Result<Vec<Vec<u8>>, TransportError> {
        let size = self.size();
        if self.rank() == 0 {
            let mut all = vec![bytes.to_vec()];
            for r in 1..size {
                all.push(self.receive(r)?);
            }
            let packed = pack(&all);
            for r in 1..size {
                self.send(r, &packed)?;
            }
            Ok(all)
        } else {
            self.send(0, bytes)?;
            unpack(&self.receive(0)?).ok_or_else(|| TransportError {
                rank: 0,
                what: "a malformed gathered message".into(),
            })
        }
    }
}

/// Messages as one: each one's length (`u64`, little-endian), then it.
fn pack(all: &[Vec<u8>]) -> Vec<u8> {
    let mut out = Vec::new();
    for m in all {
        out.extend_from_slice(&(m.len() as u64).to_le_bytes());
        out.extend_from_slice(m);
    }
    out
}

fn unpack(mut bytes: &[u8]) -> Option<Vec<Vec<u8>>> {
    let mut out = Vec::new();
    while !bytes.is_empty() {
        let len = u64::from_le_bytes(bytes.get(..8)?.try_into().ok()?) as usize;
        let body = bytes.get(8..8usize.checked_add(len)?)?;
        out.push(body.to_vec());
        bytes = &bytes[8 + len..];
    }
    Some(out)
}

/// Ranks as threads of one process, joined by channels.
pub struct Local {
    rank: usize,
    to: Vec<Sender<Vec<u8>>>,
    from: Vec<Mutex<Receiver<Vec<u8>>>>,
}

impl Local {
    /// `size` connected ranks: give one to each thread.
    pub fn group(size: usize) -> Vec<Local> {
        // Channel (a, b) carries a's messages to b.
        let mut to: Vec<Vec<Sender<Vec<u8>>>> = (0..size).map(|_| Vec::new()).collect();
        let mut from: Vec<Vec<Mutex<Receiver<Vec<u8>>>>> = (0..size).map(|_| Vec::new()).collect();
        for senders in to.iter_mut() {
            for receivers in from.iter_mut() {
                let (tx, rx) = channel();
                senders.push(tx);
                receivers.push(Mutex::new(rx));
            }
        }
        (to.into_iter().zip(from).enumerate())
            .map(|(rank, (to, from))| Local { rank, to, from })
            .collect()
    }

    fn lost(&self, other: usize) -> TransportError {
        TransportError {
            rank: other,
            what: format!("rank {} lost its link (the thread ended)", self.rank),
        }
    }
}

impl Transport for Local {
    fn rank(&self) -> usize {
        self.rank
    }

    fn size(&self) -> usize {
        self.to.len()
    }

    fn send(&self, to: usize, bytes: &[u8]) -> Result<(), TransportError> {
        self.to[to].send(bytes.to_vec()).map_err(|_| self.lost(to))
    }

    fn receive(&self, from: usize) -> Result<Vec<u8>, TransportError> {
        let rx = self.from[from].lock().map_err(|_| self.lost(from))?;
        rx.recv().map_err(|_| self.lost(from))
    }

    fn exchange(&self, partner: usize, bytes: &[u8]) -> Result<Vec<u8>, TransportError> {
        // Channels never block a sender: send, then receive.
        self.send(partner, bytes)?;
        self.receive(partner)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_rank_gathers_every_ranks_message_in_order() {
        let group = Local::group(3);
        let results: Vec<Vec<Vec<u8>>> = std::thread::scope(|s| {
            let handles: Vec<_> = (group.iter())
                .map(|t| s.spawn(move || t.all_gather(&vec![t.rank() as u8; t.rank()]).unwrap()))
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        for r in results {
            assert_eq!(r, vec![vec![], vec![1], vec![2, 2]]);
        }
    }

    #[test]
    fn partners_exchange_at_once() {
        let group = Local::group(2);
        let got: Vec<Vec<u8>> = std::thread::scope(|s| {
            let h: Vec<_> = (group.iter())
                .map(|t| s.spawn(move || t.exchange(1 - t.rank(), &[t.rank() as u8 + 7]).unwrap()))
                .collect();
            h.into_iter().map(|h| h.join().unwrap()).collect()
        });
        assert_eq!(got, vec![vec![8], vec![7]]);
    }
}
