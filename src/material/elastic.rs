//! Isotropic linear elasticity in the step-wise updated-Lagrangian setting.
//!
//! S = σ_n + D E with constant plane-strain `D` (a St. Venant–Kirchhoff law relative to x_n,
//! prestressed by σ_n). Because E is the Green–Lagrange strain, a rigid rotation produces no
//! stress change, so the model is objective for arbitrarily large rotations within a step.

use super::{GaussState, Material, MaterialError, MaterialResponse};

/// Isotropic linear elastic material.
///
/// Construct with [`LinearElastic::new`], which validates the parameters; the fields are public
/// for reading, and a value built by hand bypasses that validation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearElastic {
    /// Young's modulus E (Pa), > 0.
    pub young: f64,
    /// Poisson's ratio ν, in (-1, 0.5).
    pub poisson: f64,
}

impl LinearElastic {
    /// Validates `young > 0` and `-1 < poisson < 0.5` (both finite).
    pub fn new(young: f64, poisson: f64) -> Result<Self, MaterialError> {
        if !(young.is_finite() && young > 0.0) {
            return Err(MaterialError::InvalidParameter {
                name: "young",
                value: young,
                requirement: "0 < young < inf",
            });
        }
        // ν = 0.5 makes λ infinite in plane strain; this displacement-only element cannot
        // represent incompressibility anyway.
        if !(poisson.is_finite() && poisson > -1.0 && poisson < 0.5) {
            return Err(MaterialError::InvalidParameter {
                name: "poisson",
                value: poisson,
                requirement: "-1 < poisson < 0.5",
            });
        }
        Ok(Self { young, poisson })
    }

    /// Lamé parameters (λ, μ).
    pub fn lame(&self) -> (f64, f64) {
        let (e, nu) = (self.young, self.poisson);
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = e / (2.0 * (1.0 + nu));
        (lambda, mu)
    }

    /// Plane-strain stiffness, rows/columns `[xx, yy, zz, xy]`, engineering shear on the strain
    /// side (so `D[3][3] = μ`). The zz row gives the out-of-plane stress that plane strain induces.
    pub fn stiffness(&self) -> [[f64; 4]; 4] {
        let (l, m) = self.lame();
        let c = l + 2.0 * m;
        [
            [c, l, l, 0.0],
            [l, c, l, 0.0],
            [l, l, c, 0.0],
            [0.0, 0.0, 0.0, m],
        ]
    }
}

impl Material for LinearElastic {
    fn update(
        &self,
        state_n: &GaussState,
        e: &[f64; 4],
    ) -> Result<MaterialResponse, MaterialError> {
        if e.iter().any(|v| !v.is_finite()) {
            return Err(MaterialError::NonFiniteStrain { strain: *e });
        }
        let d = self.stiffness();
        let mut s = state_n.stress;
        for (si, row) in s.iter_mut().zip(d.iter()) {
            *si += row
                .iter()
                .zip(e.iter())
                .map(|(dij, ej)| dij * ej)
                .sum::<f64>();
        }
        Ok(MaterialResponse {
            s,
            d,
            state: state_n.clone(),
        })
    }

    fn name(&self) -> &'static str {
        "linear_elastic"
    }

    fn isochoric(&self) -> bool {
        true
    }
}

#[cfg(test)]
// Index loops mirror the component notation of the formulas being checked.
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs().max(1.0)
    }

    #[test]
    fn plane_strain_values_for_e12e6_nu02() {
        let m = LinearElastic::new(12e6, 0.2).expect("valid parameters");
        let (l, mu) = m.lame();
        assert!(close(l, 12e6 * 0.2 / (1.2 * 0.6), 1e-14));
        assert!(close(mu, 5e6, 1e-14));
        let d = m.stiffness();
        // Closed forms: D11 = E(1-ν)/((1+ν)(1-2ν)), D12 = Eν/((1+ν)(1-2ν)), D44 = E/(2(1+ν)).
        let d11 = 12e6 * 0.8 / (1.2 * 0.6);
        let d12 = 12e6 * 0.2 / (1.2 * 0.6);
        assert!(close(d11, 13_333_333.333_333_334, 1e-14));
        for i in 0..3 {
            for j in 0..3 {
                let want = if i == j { d11 } else { d12 };
                assert!(close(d[i][j], want, 1e-14), "D[{i}][{j}] = {}", d[i][j]);
            }
            assert_eq!(d[i][3], 0.0);
            assert_eq!(d[3][i], 0.0);
        }
        assert!(close(d[3][3], 5e6, 1e-14));
    }

    #[test]
    fn tangent_is_symmetric() {
        let m = LinearElastic::new(3.7e7, 0.31).expect("valid parameters");
        let d = m.stiffness();
        for (i, row) in d.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                assert_eq!(*v, d[j][i]);
            }
        }
    }

    #[test]
    fn update_adds_elastic_increment_to_prestress() {
        let m = LinearElastic::new(12e6, 0.2).expect("valid parameters");
        let st = GaussState {
            stress: [-1e5, -2e5, -1.5e5, 3e4],
            ..GaussState::default()
        };
        let e = [1e-3, -2e-3, 0.0, 5e-4];
        let r = m.update(&st, &e).expect("finite strain");
        let (l, mu) = m.lame();
        let tr = e[0] + e[1];
        let want = [
            st.stress[0] + l * tr + 2.0 * mu * e[0],
            st.stress[1] + l * tr + 2.0 * mu * e[1],
            st.stress[2] + l * tr,
            st.stress[3] + mu * e[3],
        ];
        for k in 0..4 {
            assert!(
                close(r.s[k], want[k], 1e-13),
                "S[{k}] {} vs {}",
                r.s[k],
                want[k]
            );
        }
        assert!(r.state.internal.is_empty());
        assert_eq!(m.name(), "linear_elastic");
    }

    #[test]
    fn rejects_bad_parameters_naming_the_field() {
        for (e, nu, field) in [
            (0.0, 0.2, "young"),
            (-1.0, 0.2, "young"),
            (f64::NAN, 0.2, "young"),
            (1e6, 0.5, "poisson"),
            (1e6, -1.0, "poisson"),
            (1e6, f64::NAN, "poisson"),
        ] {
            match LinearElastic::new(e, nu) {
                Err(err @ MaterialError::InvalidParameter { name, .. }) => {
                    assert_eq!(name, field);
                    assert!(err.to_string().contains(field));
                }
                other => panic!("expected rejection of ({e}, {nu}), got {other:?}"),
            }
        }
        assert!(LinearElastic::new(1e6, -0.99).is_ok());
        assert!(LinearElastic::new(1e6, 0.499).is_ok());
    }

    #[test]
    fn rejects_non_finite_strain() {
        let m = LinearElastic::new(1e6, 0.3).expect("valid parameters");
        let r = m.update(&GaussState::default(), &[f64::NAN, 0.0, 0.0, 0.0]);
        assert!(matches!(r, Err(MaterialError::NonFiniteStrain { .. })));
    }
}
