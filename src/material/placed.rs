//! A model working in the state layout of a scene with several materials. The scene's rows hold
//! the union of every model's internal variables (by name); each model reads and writes its own
//! variables in its own order, and leaves the others (another material's, met only across an
//! interface) as they were.

use super::layout::{internal_len, InternalVar, StateLayout, STRESS_LEN};
use super::{GaussState, Internal, Material, MaterialError, MaterialResponse};

/// `inner` placed in the union layout `vars`.
#[derive(Debug)]
pub struct Placed {
    inner: Box<dyn Material>,
    vars: Vec<InternalVar>,
    /// For each of `inner`'s internal scalars, its position in the union's internal scalars;
    /// None when the two layouts agree on `inner`'s part (no copy needed).
    map: Option<Vec<usize>>,
    union_len: usize,
}

/// The union of the layouts of `models`: each variable once, in order of first appearance.
pub fn union_layout<'a>(models: impl IntoIterator<Item = &'a [InternalVar]>) -> StateLayout {
    let mut vars: Vec<InternalVar> = Vec::new();
    for m in models {
        for v in m {
            match vars.iter().find(|u| u.name == v.name) {
                Some(u) => assert_eq!(
                    u.kind, v.kind,
                    "two models declare `{}` with different kinds",
                    v.name
                ),
                None => vars.push(v.clone()),
            }
        }
    }
    StateLayout::new(&vars)
}

impl Placed {
    /// `inner` in `union`, which must hold every variable of `inner` ([`union_layout`]).
    pub fn new(inner: Box<dyn Material>, union: &StateLayout) -> Result<Placed, String> {
        let mut map = Vec::new();
        for v in inner.internal_variables() {
            let Some((at, _)) = union.find(&v.name) else {
                return Err(format!(
                    "model \"{}\" keeps `{}`, which the scene's state layout lacks",
                    inner.name(),
                    v.name
                ));
            };
            map.extend((0..v.kind.width()).map(|k| at - STRESS_LEN + k));
        }
        let identity = map.iter().enumerate().all(|(i, &j)| i == j);
        Ok(Placed {
            inner,
            vars: union.vars().to_vec(),
            map: (!identity).then_some(map),
            union_len: union.internal_len(),
        })
    }

    /// The state as `inner` lays it out.
    fn own(&self, s: &GaussState) -> GaussState {
        match &self.map {
            None => {
                let n = internal_len(self.inner.internal_variables()).min(s.internal.len());
                GaussState {
                    stress: s.stress,
                    internal: Internal::from_slice(&s.internal[..n]),
                }
            }
            Some(map) => GaussState {
                stress: s.stress,
                internal: map
                    .iter()
                    .map(|&j| s.internal.get(j).copied().unwrap_or(0.0))
                    .collect(),
            },
        }
    }

    /// `own` (in `inner`'s layout) written back over `union` (in the union layout).
    fn back(&self, union: &GaussState, own: GaussState) -> GaussState {
        let mut out = union.clone();
        out.internal.resize(self.union_len, 0.0);
        out.stress = own.stress;
        match &self.map {
            None => out.internal[..own.internal.len()].copy_from_slice(&own.internal),
            Some(map) => {
                for (&j, &x) in map.iter().zip(own.internal.iter()) {
                    out.internal[j] = x;
                }
            }
        }
        out
    }

    fn respond(
        &self,
        state_n: &GaussState,
        r: Result<MaterialResponse, MaterialError>,
    ) -> Result<MaterialResponse, MaterialError> {
        r.map(|r| MaterialResponse {
            state: self.back(state_n, r.state),
            ..r
        })
    }
}

impl Material for Placed {
    fn update(
        &self,
        state_n: &GaussState,
        e: &[f64; 4],
    ) -> Result<MaterialResponse, MaterialError> {
        self.respond(state_n, self.inner.update(&self.own(state_n), e))
    }

    fn update_log_strain(
        &self,
        state_n: &GaussState,
        eps: &[f64; 4],
    ) -> Result<MaterialResponse, MaterialError> {
        self.respond(
            state_n,
            self.inner.update_log_strain(&self.own(state_n), eps),
        )
    }

    fn name(&self) -> &'static str {
        self.inner.name()
    }

    fn internal_variables(&self) -> &[InternalVar] {
        &self.vars
    }

    fn initial_internal(&self, x0: [f64; 2], internal: &mut [f64]) {
        let mut own = vec![0.0; internal_len(self.inner.internal_variables())];
        self.inner.initial_internal(x0, &mut own);
        match &self.map {
            None => internal[..own.len()].copy_from_slice(&own),
            Some(map) => map.iter().zip(&own).for_each(|(&j, &x)| internal[j] = x),
        }
    }

    fn yields(&self) -> bool {
        self.inner.yields()
    }

    fn yielded(&self, before: &GaussState, after: &GaussState) -> bool {
        self.inner.yielded(&self.own(before), &self.own(after))
    }

    fn symmetric_tangent(&self) -> bool {
        self.inner.symmetric_tangent()
    }

    fn isochoric(&self) -> bool {
        self.inner.isochoric()
    }

    fn bulk_at(&self, state: &GaussState) -> Option<f64> {
        self.inner.bulk_at(&self.own(state))
    }

    fn admit(&self, state: &mut GaussState) -> bool {
        let mut own = self.own(state);
        if !self.inner.admit(&mut own) {
            return false;
        }
        *state = self.back(state, own);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::elastic::LinearElastic;
    use crate::material::tresca::{Tresca, EPS_Q};

    #[test]
    fn each_model_keeps_its_own_variables_in_the_union() {
        let t = Tresca::new(3e6, 0.49, 1e4).unwrap();
        let e = LinearElastic::new(1e7, 0.3).unwrap();
        let union = union_layout([e.internal_variables(), t.internal_variables()]);
        assert_eq!(union.len(), 9);
        let elastic = Placed::new(Box::new(e), &union).unwrap();
        let tresca = Placed::new(Box::new(t), &union).unwrap();
        assert_eq!(elastic.internal_variables().len(), 2);
        // The elastic law leaves the plastic columns it meets as they were.
        let mut s = GaussState::stressed([0.0; 4], 5);
        s.internal[EPS_Q] = 0.25;
        let r = elastic.update(&s, &[1e-4, 0.0, 0.0, 0.0]).unwrap();
        assert_eq!(r.state.internal[EPS_Q], 0.25);
        // Tresca flows in the union layout as it does alone.
        let strain = [0.0, 0.0, 0.0, 0.05];
        let alone = t.update(&GaussState::default(), &strain).unwrap();
        let placed = tresca
            .update(&GaussState::stressed([0.0; 4], 5), &strain)
            .unwrap();
        assert_eq!(alone.state.internal, placed.state.internal);
        assert!(tresca.yielded(&GaussState::stressed([0.0; 4], 5), &placed.state));
    }
}
