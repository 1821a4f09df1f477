//! The particles one rank owns, sorted by global id, and the halo copies of its neighbours'.

use crate::material::Rows;
use pfem_partition::{Comm, Halo, PartitionError};

/// Per-particle flags.
pub mod flag {
    /// Tracked by a point load: never removed or smoothed.
    pub const TRACKED: u32 = 1;
}

/// Owned particles (structure of arrays, sorted by global id).
#[derive(Debug, Clone, Default)]
pub struct Particles {
    pub gid: Vec<u64>,
    pub position: Vec<[f64; 2]>,
    /// Total displacement since the start of the analysis; position − displacement is the
    /// reference position that boundary selectors look at.
    pub displacement: Vec<[f64; 2]>,
    /// Displacement increment of the last step: the next step's Newton predictor.
    pub increment: Vec<[f64; 2]>,
    /// Target spacing.
    pub h: Vec<f64>,
    /// State carried by the particle (Gauss state recovered at the particle), one row of the
    /// material's layout each.
    pub state: Rows,
    pub flags: Vec<u32>,
    /// Index of the particle's material in the scene's `[[material]]` list.
    pub material: Vec<u32>,
}

/// A particle closer to the axis of an axisymmetric body than this fraction of its spacing is
/// put on it. Half the spacing, not less: particles on the axis only move along it, and those
/// behind a penetrating body are merged at its rear stagnation point, so the axis is stripped
/// behind the body; soil closing in from the sides must be put back on it, or a slit a few
/// millimetres wide stays open along the axis in the wake (the `ball` lost 2-7 % of its
/// resistance after w/D = 0.85 with a tenth of the spacing).
pub const AXIS_SNAP: f64 = 0.5;

impl Particles {
    /// Rank-local. Puts on the axis (x = 0) every particle that has come within [`AXIS_SNAP`] of
    /// its spacing of it, keeping its reference position; from then on the axis holds it
    /// radially. Off it, its triangles are slivers whose hoop stretch 1 + u_r/r Newton drives
    /// through zero: on the spudcan a particle under the tip crept 0.057 → 0.040 → 0.020 →
    /// 0.005 m (h = 0.5 m) towards the axis in four steps, and Newton then crawled (line search
    /// λ ≈ 0.006) and failed in the fifth. `onto(x, h)` says where on the axis a particle whose
    /// place there is `x` goes (`x`, or along the axis out of a rigid body it lies in), `None` to
    /// leave it off the axis. Returns how many were moved.
    pub fn snap_to_axis(&mut self, onto: impl Fn([f64; 2], f64) -> Option<[f64; 2]>) -> usize {
        let mut moved = 0;
        for i in 0..self.position.len() {
            let x = self.position[i];
            if x[0] == 0.0 || x[0] >= AXIS_SNAP * self.h[i] {
                continue;
            }
            let Some(to) = onto([0.0, x[1]], self.h[i]) else {
                continue;
            };
            self.position[i] = [0.0, to[1]];
            self.displacement[i][0] -= x[0];
            self.displacement[i][1] += to[1] - x[1];
            self.increment[i][0] = 0.0;
            moved += 1;
        }
        moved
    }
}

/// Copies of other ranks' particles near ours, bit for bit, in the halo's ghost order.
#[derive(Debug, Clone, Default)]
pub struct Ghosts {
    pub gid: Vec<u64>,
    pub owner: Vec<i32>,
    pub position: Vec<[f64; 2]>,
    pub displacement: Vec<[f64; 2]>,
    pub increment: Vec<[f64; 2]>,
    pub h: Vec<f64>,
    pub state: Rows,
    pub material: Vec<u32>,
}

/// f64 values per particle in a halo exchange before its state row: position, displacement,
/// increment, h, material index (exact in an f64).
const FIXED: usize = 8;

impl Particles {
    pub fn len(&self) -> usize {
        self.gid.len()
    }

    pub fn is_empty(&self) -> bool {
        self.gid.is_empty()
    }

    pub fn reference_position(&self, i: usize) -> [f64; 2] {
        [
            self.position[i][0] - self.displacement[i][0],
            self.position[i][1] - self.displacement[i][1],
        ]
    }

    /// Sorts by global id (the invariant every other structure relies on).
    pub fn sort_by_gid(&mut self) {
        let mut order: Vec<usize> = (0..self.len()).collect();
        order.sort_by_key(|&i| self.gid[i]);
        self.gid = order.iter().map(|&i| self.gid[i]).collect();
        self.position = order.iter().map(|&i| self.position[i]).collect();
        self.displacement = order.iter().map(|&i| self.displacement[i]).collect();
        self.increment = order.iter().map(|&i| self.increment[i]).collect();
        self.h = order.iter().map(|&i| self.h[i]).collect();
        self.state = self.state.permuted(&order);
        self.flags = order.iter().map(|&i| self.flags[i]).collect();
        self.material = order.iter().map(|&i| self.material[i]).collect();
    }

    /// f64 values per particle in [`Particles::records`].
    pub fn record_len(&self) -> usize {
        FIXED + self.state.width()
    }

    /// Flattens the f64 fields for exchange and migration.
    pub fn records(&self) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.len() * self.record_len());
        for i in 0..self.len() {
            out.extend_from_slice(&self.position[i]);
            out.extend_from_slice(&self.displacement[i]);
            out.extend_from_slice(&self.increment[i]);
            out.push(self.h[i]);
            out.push(f64::from(self.material[i]));
            out.extend_from_slice(self.state.row(i));
        }
        out
    }

    /// Rebuilds from global ids, flattened records of [`Particles::records`] (state rows of
    /// `width`) and flags.
    pub fn from_records(gid: Vec<u64>, rec: &[f64], width: usize, flags: Vec<u32>) -> Particles {
        let mut p = Particles {
            gid,
            flags,
            state: Rows::with_capacity(width, rec.len() / (FIXED + width)),
            ..Default::default()
        };
        for r in rec.chunks_exact(FIXED + width) {
            p.position.push([r[0], r[1]]);
            p.displacement.push([r[2], r[3]]);
            p.increment.push([r[4], r[5]]);
            p.h.push(r[6]);
            p.material.push(r[7] as u32);
            p.state.push(&r[FIXED..]);
        }
        p
    }

    /// Collective. Builds the halo of width `width` and copies the neighbours' particles.
    pub fn ghosts(&self, comm: &Comm, width: f64) -> Result<(Halo, Ghosts), PartitionError> {
        let halo = Halo::build(comm, &self.gid, &self.position, width)?;
        let len = self.record_len();
        let rec = halo.exchange_f64(comm, &self.records(), len);
        let mut g = Ghosts {
            gid: halo.ghost_ids().to_vec(),
            owner: halo.ghost_owners().to_vec(),
            state: Rows::with_capacity(self.state.width(), rec.len() / len),
            ..Default::default()
        };
        for r in rec.chunks_exact(len) {
            g.position.push([r[0], r[1]]);
            g.displacement.push([r[2], r[3]]);
            g.increment.push([r[4], r[5]]);
            g.h.push(r[6]);
            g.material.push(r[7] as u32);
            g.state.push(&r[FIXED..]);
        }
        Ok((halo, g))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn particles_near_the_axis_are_put_on_it_keeping_their_reference_position() {
        let mut p = Particles {
            gid: vec![1, 2, 3, 4],
            position: vec![[0.04, 1.0], [0.3, 2.0], [0.0, 3.0], [-0.01, 4.0]],
            displacement: vec![[-0.01, 0.5], [0.0, 0.0], [0.0, 0.0], [-0.02, 0.0]],
            increment: vec![[-0.01, 0.1]; 4],
            h: vec![0.5, 0.5, 0.5, 0.5],
            state: Rows::default(),
            flags: vec![0; 4],
            material: vec![0; 4],
        };
        let reference: Vec<f64> = (0..4)
            .map(|i| p.position[i][0] - p.displacement[i][0])
            .collect();
        assert_eq!(p.snap_to_axis(|x, _| Some(x)), 2);
        assert_eq!(p.position[0], [0.0, 1.0]);
        assert_eq!(p.position[1], [0.3, 2.0], "0.6 h off the axis stays");
        assert_eq!(p.position[2], [0.0, 3.0]);
        assert_eq!(
            p.position[3],
            [0.0, 4.0],
            "a particle past the axis comes back onto it"
        );
        assert_eq!(p.increment[0], [0.0, 0.1]);
        assert_eq!(p.increment[1], [-0.01, 0.1]);
        for (i, r) in reference.iter().enumerate() {
            assert!((p.position[i][0] - p.displacement[i][0] - r).abs() < 1e-15);
        }
        // Moved along the axis where `onto` says, or left off it.
        p.position[0] = [0.1, 1.0];
        p.position[2] = [0.1, 0.5];
        let before = p.displacement[0];
        let onto = |x: [f64; 2], _| (x[1] < 0.9).then_some(x).or(Some([0.0, 0.8]));
        assert_eq!(p.snap_to_axis(onto), 2);
        assert_eq!(p.position[0], [0.0, 0.8]);
        let d = p.displacement[0];
        assert!((d[0] - before[0] + 0.1).abs() < 1e-15 && (d[1] - before[1] + 0.2).abs() < 1e-15);
        assert_eq!(p.position[2], [0.0, 0.5]);
        p.position[0] = [0.1, 1.0];
        assert_eq!(p.snap_to_axis(|_, _| None), 0);
        assert_eq!(p.position[0], [0.1, 1.0]);
    }
}
