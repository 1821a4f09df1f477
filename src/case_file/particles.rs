//! Particles as parallel arrays, the unit that case files store and ranks exchange.

use crate::material::Rows;

/// A set of particles, one entry per particle in each array (all arrays have the same length).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ParticleSet {
    /// Global particle id, unique over all ranks.
    pub gid: Vec<u64>,
    /// Current position (m).
    pub position: Vec<[f64; 2]>,
    /// Total displacement since the start of the analysis (m).
    pub displacement: Vec<[f64; 2]>,
    /// Displacement increment of the last step (m): the next step's Newton predictor.
    pub increment: Vec<[f64; 2]>,
    /// Local particle spacing (m).
    pub h: Vec<f64>,
    /// Per-particle material state, one row of the material's layout each
    /// ([`crate::material::StateLayout`]).
    pub state: Rows,
    /// Per-particle bit flags.
    pub flags: Vec<u32>,
    /// Index of each particle's material in the scene's `[[material]]` list.
    pub material: Vec<u32>,
}

impl ParticleSet {
    /// Room for `n` particles with state rows of `width`.
    pub fn with_capacity(n: usize, width: usize) -> Self {
        ParticleSet {
            gid: Vec::with_capacity(n),
            position: Vec::with_capacity(n),
            displacement: Vec::with_capacity(n),
            increment: Vec::with_capacity(n),
            h: Vec::with_capacity(n),
            state: Rows::with_capacity(width, n),
            flags: Vec::with_capacity(n),
            material: Vec::with_capacity(n),
        }
    }

    pub fn len(&self) -> usize {
        self.gid.len()
    }

    pub fn is_empty(&self) -> bool {
        self.gid.is_empty()
    }

    /// Appends a particle at rest: zero displacement, state, flags and material index.
    pub fn push_new(&mut self, gid: u64, position: [f64; 2], h: f64) {
        self.gid.push(gid);
        self.position.push(position);
        self.displacement.push([0.0; 2]);
        self.increment.push([0.0; 2]);
        self.h.push(h);
        self.state.push_zeros();
        self.flags.push(0);
        self.material.push(0);
    }

    /// The particles at indices `range`, copied.
    pub fn slice(&self, range: std::ops::Range<usize>) -> ParticleSet {
        ParticleSet {
            gid: self.gid[range.clone()].to_vec(),
            position: self.position[range.clone()].to_vec(),
            displacement: self.displacement[range.clone()].to_vec(),
            increment: self.increment[range.clone()].to_vec(),
            h: self.h[range.clone()].to_vec(),
            state: self.state.slice(range.clone()),
            flags: self.flags[range.clone()].to_vec(),
            material: self.material[range].to_vec(),
        }
    }

    /// Moves all particles of `other` to the end of `self`.
    pub fn append(&mut self, other: &mut ParticleSet) {
        self.gid.append(&mut other.gid);
        self.position.append(&mut other.position);
        self.displacement.append(&mut other.displacement);
        self.increment.append(&mut other.increment);
        self.h.append(&mut other.h);
        self.state.append(&mut other.state);
        self.flags.append(&mut other.flags);
        self.material.append(&mut other.material);
    }

    /// Names the first array whose length differs from `gid`'s.
    pub fn check_lengths(&self) -> Result<(), String> {
        let n = self.gid.len();
        let lens = [
            ("position", self.position.len()),
            ("displacement", self.displacement.len()),
            ("increment", self.increment.len()),
            ("h", self.h.len()),
            ("state", self.state.len()),
            ("flags", self.flags.len()),
            ("material", self.material.len()),
        ];
        match lens.iter().find(|(_, len)| *len != n) {
            Some((name, len)) => Err(format!(
                "particle set is inconsistent: {n} gids but {len} {name} entries"
            )),
            None => Ok(()),
        }
    }

    /// `[[xmin, ymin], [xmax, ymax]]` of the positions, None when empty.
    pub fn bounding_box(&self) -> Option<[[f64; 2]; 2]> {
        let first = *self.position.first()?;
        Some(self.position.iter().fold([first, first], |bb, p| {
            [
                [bb[0][0].min(p[0]), bb[0][1].min(p[1])],
                [bb[1][0].max(p[0]), bb[1][1].max(p[1])],
            ]
        }))
    }
}
