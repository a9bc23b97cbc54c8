//! Who sends what to whom: binary swap over the k-d tree, with the ranks
//! beyond a power of two folded in first.
//!
//! Binary swap (Ma, Painter, Hansen & Krogh, "Parallel volume rendering
//! using binary-swap compositing", IEEE CG&A 1994) composites `2^d` images
//! in `d` rounds: in round `r` each rank pairs with the rank whose subtree
//! is its sibling at that level of the k-d tree, the two split the part of
//! the image they hold in half, each sends the other half and composites
//! the half it keeps, front over back by the cut between their subtrees.
//! Every rank sends `(1 − 2^−d)` of an image in all, and ends holding
//! `1/2^d` of the final image.
//!
//! For `N` ranks, not a power of two, the k-d tree has its leaves at depths
//! `d = ⌊log₂ N⌋` and `d + 1` ([`crate::kd`]); the `2(N − 2^d)` leaves at
//! depth `d + 1` are sibling pairs. First each pair folds: the high
//! sibling sends its whole image to the low one, which composites the two
//! by their cut (one extra round, `N − 2^d` messages). The `2^d` ranks left
//! are the leaves of a perfect tree of depth `d`, and swap.

use crate::kd::{Decomposition, Node};

/// A cut of the k-d tree: which side of it a rank's image comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cut {
    pub axis: usize,
    /// The voxel plane of the cut.
    pub at: usize,
    /// Whether this rank's image is of the low side (`i < at`).
    pub mine_low: bool,
}

/// A fold before the swaps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fold {
    /// Send the whole image to `to`, and take no further part.
    Send { to: usize },
    /// Receive a whole image from `from` and composite it with this one.
    Receive { from: usize, cut: Cut },
}

/// One round of binary swap.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Swap {
    pub partner: usize,
    /// Keep the first half of the rows held (send the second), or the
    /// second (send the first).
    pub keep_first: bool,
    pub cut: Cut,
}

/// What one rank does to composite.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Plan {
    pub fold: Option<Fold>,
    pub swaps: Vec<Swap>,
    /// The ranks that hold a part of the image after the swaps, by their
    /// index in the perfect tree (rank 0 first); the gather reads them.
    pub leaders: Vec<usize>,
}

/// A node at depth `d` of the tree: its leader, the rank folded into it
/// (if any, with the cut between them), and the cuts above it.
struct Group {
    leader: usize,
    folded: Option<(usize, usize, usize)>,
    ancestors: Vec<(usize, usize)>,
}

impl Plan {
    /// The plan of rank `rank` in `decomposition`.
    pub fn new(decomposition: &Decomposition, rank: usize) -> Plan {
        let ranks = decomposition.boxes.len();
        let depth = ranks.ilog2() as usize;
        let mut groups = Vec::with_capacity(1 << depth);
        collect(&decomposition.root, depth, &mut Vec::new(), &mut groups);
        debug_assert_eq!(groups.len(), 1 << depth);
        let leaders: Vec<usize> = groups.iter().map(|g| g.leader).collect();
        let mut plan = Plan {
            fold: None,
            swaps: Vec::new(),
            leaders: leaders.clone(),
        };
        for (index, group) in groups.iter().enumerate() {
            if let Some((high, axis, at)) = group.folded {
                if rank == high {
                    plan.fold = Some(Fold::Send { to: group.leader });
                    return plan;
                }
                if rank == group.leader {
                    plan.fold = Some(Fold::Receive {
                        from: high,
                        cut: Cut {
                            axis,
                            at,
                            mine_low: true,
                        },
                    });
                }
            }
            if rank != group.leader {
                continue;
            }
            // Round r pairs the groups differing in bit r of their index:
            // siblings below the cut at depth d − 1 − r.
            for r in 0..depth {
                let bit = (index >> r) & 1;
                let (axis, at) = group.ancestors[depth - 1 - r];
                plan.swaps.push(Swap {
                    partner: leaders[index ^ (1 << r)],
                    keep_first: bit == 0,
                    cut: Cut {
                        axis,
                        at,
                        mine_low: bit == 0,
                    },
                });
            }
        }
        plan
    }
}

/// The nodes at depth `depth` below `node`, in order, with the cuts above.
fn collect(node: &Node, depth: usize, above: &mut Vec<(usize, usize)>, out: &mut Vec<Group>) {
    match node {
        Node::Leaf { rank } => {
            assert_eq!(above.len(), depth, "a leaf above the fold depth");
            out.push(Group {
                leader: *rank,
                folded: None,
                ancestors: above.clone(),
            });
        }
        Node::Split {
            axis,
            cut,
            low,
            high,
        } => {
            if above.len() == depth {
                let (Node::Leaf { rank: l }, Node::Leaf { rank: h }) = (&**low, &**high) else {
                    panic!("the k-d tree is deeper than ⌊log₂ N⌋ + 1");
                };
                out.push(Group {
                    leader: *l,
                    folded: Some((*h, *axis, *cut)),
                    ancestors: above.clone(),
                });
                return;
            }
            above.push((*axis, *cut));
            collect(low, depth, above, out);
            collect(high, depth, above, out);
            above.pop();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn powers_of_two_swap_with_the_rank_across_each_level() {
        let d = Decomposition::new([64, 64, 64], 4);
        let plan = Plan::new(&d, 1);
        assert_eq!(plan.fold, None);
        assert_eq!(plan.leaders, vec![0, 1, 2, 3]);
        let partners: Vec<usize> = plan.swaps.iter().map(|s| s.partner).collect();
        assert_eq!(partners, vec![0, 3]);
        assert!(!plan.swaps[0].keep_first && plan.swaps[1].keep_first);
    }

    #[test]
    fn ranks_beyond_a_power_of_two_fold_into_their_siblings() {
        for ranks in 1..=12 {
            let d = Decomposition::new([50, 40, 30], ranks);
            let plans: Vec<Plan> = (0..ranks).map(|r| Plan::new(&d, r)).collect();
            let p = 1 << ranks.ilog2();
            let senders = plans
                .iter()
                .filter(|p| matches!(p.fold, Some(Fold::Send { .. })))
                .count();
            assert_eq!(senders, ranks - p, "{ranks} ranks");
            // Every fold is received by the one it is sent to, and every
            // swap is mirrored by its partner, with the other half.
            for (rank, plan) in plans.iter().enumerate() {
                match plan.fold {
                    Some(Fold::Send { to }) => {
                        assert!(plan.swaps.is_empty());
                        assert!(
                            matches!(plans[to].fold, Some(Fold::Receive { from, .. }) if from == rank)
                        );
                    }
                    _ => assert_eq!(plan.swaps.len(), p.ilog2() as usize),
                }
                for (r, s) in plan.swaps.iter().enumerate() {
                    let back = plans[s.partner].swaps[r];
                    assert_eq!(back.partner, rank);
                    assert_ne!(back.keep_first, s.keep_first);
                    assert_eq!((back.cut.axis, back.cut.at), (s.cut.axis, s.cut.at));
                    assert_ne!(back.cut.mine_low, s.cut.mine_low);
                }
            }
            assert_eq!(plans[0].leaders[0], 0);
        }
    }
}
