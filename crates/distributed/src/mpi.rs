//! The transport over MPI (rsmpi): `MPI_COMM_WORLD`'s ranks, byte messages
//! point to point. Build with `--features mpi` against an MPI
//! implementation (Open MPI or MPICH); run under `mpirun`.

use crate::transport::{Transport, TransportError};
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;

/// MPI, initialised for this process (finalised when dropped).
pub struct Mpi {
    _universe: mpi::environment::Universe,
    world: SimpleCommunicator,
}

impl Mpi {
    /// Initialises MPI, or `None` if it is already initialised or cannot be.
    pub fn initialize() -> Option<Mpi> {
        let universe = mpi::initialize()?;
        let world = universe.world();
        Some(Mpi {
            _universe: universe,
            world,
        })
    }

    /// Wall-clock seconds (`MPI_Wtime`).
    pub fn time(&self) -> f64 {
        mpi::time()
    }

    /// Ends every rank of the run with `code` (`MPI_Abort`): for a rank that
    /// cannot go on and cannot tell the others otherwise.
    pub fn abort(&self, code: i32) -> ! {
        self.world.abort(code)
    }
}

/// Ends every rank of the run with `code` (`MPI_Abort` on the world),
/// from anywhere (a panic hook, say).
pub fn abort_world(code: i32) -> ! {
    SimpleCommunicator::world().abort(code)
}

/// Whether this process was started by an MPI launcher (`mpirun`,
/// `mpiexec`, `srun`): the variables Open MPI, MPICH (PMI) and PMIx set.
pub fn launched() -> bool {
    ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "PMI_RANK"]
        .iter()
        .any(|v| std::env::var_os(v).is_some())
}

impl Transport for Mpi {
    fn rank(&self) -> usize {
        self.world.rank() as usize
    }

    fn size(&self) -> usize {
        self.world.size() as usize
    }

    fn send(&self, to: usize, bytes: &[u8]) -> Result<(), TransportError> {
        // rsmpi aborts the run on an MPI error (MPI_ERRORS_ARE_FATAL): a
        // lost rank ends every rank rather than leaving one waiting.
        self.world.process_at_rank(to as i32).send(bytes);
        Ok(())
    }

    fn receive(&self, from: usize) -> Result<Vec<u8>, TransportError> {
        let (bytes, _status) = self.world.process_at_rank(from as i32).receive_vec::<u8>();
        Ok(bytes)
    }

    fn exchange(&self, partner: usize, bytes: &[u8]) -> Result<Vec<u8>, TransportError> {
        let process = self.world.process_at_rank(partner as i32);
        // Both partners send at once: the send must not wait for the
        // receive, so it is posted first and completed after it.
        let received = mpi::request::scope(|scope| {
            let sent = process.immediate_send(scope, bytes);
            let (received, _status) = process.receive_vec::<u8>();
            sent.wait();
            received
        });
        Ok(received)
    }
}
