//! Mixed u–p Taylor–Hood (P2–P1) element for nearly incompressible and plastically
//! incompressible materials (undrained clay), with an objective logarithmic-strain step update.
//!
//! # Unknowns
//! The step displacement Δu at the six P2 nodes ([`crate::fem::p2`] order) and the end-of-step
//! Cauchy pressure p = −tr σ / 3 (compression positive) at the three vertices, interpolated
//! linearly (the area coordinates). Dof order: the 12 displacement dofs of
//! [`crate::fem::element`] (node0 ux, node0 uy, …, node5 uy), then p0, p1, p2.
//!
//! # Kinematics and stress update (per Gauss point of the 3-point rule)
//! Reference configuration: the start-of-step positions x_n. H = ∂Δu/∂x_n, F = I + H,
//! J = det F. With the polar decomposition F = R U:
//! - step strain: ε = ln U = ½ ln(FᵀF), evaluated in closed form (see [`log_strain`]);
//! - deviatoric stress: the material's rotation-free response ŝ, the deviator of
//!   [`Material::update_log_strain`] at (σ_n, ε) (for the Tresca model: radial return of
//!   dev σ_n + 2G dev ε);
//! - end-of-step Cauchy stress: σ_{n+1} = R ŝ Rᵀ − p I (σzz = ŝzz − p).
//!
//! Why not the Green–Lagrange / 2nd Piola–Kirchhoff pair of [`crate::fem::element`]: there the
//! yield condition is imposed on S, and σ = F S Fᵀ/J departs from it by O(|H| |σ|): continuing
//! plastic shear from the yield surface, the in-plane shear misses cu by 1e-2 cu (step 1e-3) to
//! 0.1 cu (step 1e-2) at a mean stress of 10 cu, and by 3e-3 cu to 5e-3 cu for a 1e-2 step even
//! at zero mean stress (test `end_of_step_cauchy_stress_is_on_the_yield_surface`).
//! Here R ŝ Rᵀ has the invariants of ŝ, and −p I has no deviator, so σ_{n+1} satisfies the yield
//! condition to round-off whatever the pressure, the rotation or the step size. The update is
//! objective: a rigid step F = Q gives U = I, ε = 0, R = Q and σ_{n+1} = Q σ_n Qᵀ exactly, and a
//! superposed rotation leaves ε unchanged and rotates σ_{n+1}. It is the incrementally objective
//! ("rotation-neutralised", Green–Naghdi-type) hypoelastic–plastic update. For zero prestress it
//! agrees with the elastic P2 element to O(|H|²); with a prestress σ_n the two differ at
//! O(|H| |σ_n|), the first-order difference between the Truesdell rate implied by F S Fᵀ/J and
//! the corotational rate used here (relative to the elastic increment this is |σ_n|/G).
//! Plastic strain is rotated with the stress: ε^p_{n+1} = R ε^p Rᵀ.
//!
//! # Weak form
//! - momentum: r_a = ∫_{Ω_n} τ ∇_x N_a dV − ∫_{Ω_n} N_a b dV, τ = J σ_{n+1} the Kirchhoff stress
//!   (this is ∫_{Ω_{n+1}} σ ∇N_a dv, pulled back to x_n);
//! - volume: r_i = −∫_{Ω_n} L_i [ (J − 1) + (p − p_n)/K ] dV, with L_i the P1 functions and p_n
//!   the start-of-step pressure at the Gauss point (from `states_n`).
//!
//! g(J) = J − 1 is the constraint conjugate to the Cauchy pressure: the pressure's virtual work
//! over Ω_{n+1} is −∫_{Ω_n} p δJ dV, so ∂r_u/∂p = (∂r_p/∂u)ᵀ *exactly* (a symmetric saddle
//! point; ln J would leave a factor J between the two blocks). K = ∞ (`bulk = f64::INFINITY`)
//! enforces J = 1 weakly, exact incompressibility; finite K gives the pressure law
//! p = p_n − K (J − 1) = p_n − K ln J + O(K (J−1)²), the pure-displacement response of a
//! compressible material with bulk modulus K. The pressure block is −∫ L_i L_j / K dV ≤ 0.
//!
//! The deviatoric block is the consistent linearisation of the update above; it is symmetric up
//! to terms of order |σ|/G from the rotation of the stress (a corotational update derives from
//! no potential; measured ‖K_uu − K_uuᵀ‖/‖K_uu‖ = 2e-3 at |σ|/G = 3e-2). Factor the global
//! matrix as unsymmetric for quadratic Newton convergence; a symmetric factorisation of its
//! symmetric part is a valid but only linearly convergent Newton variant.
//!
//! # Pressure-dependent and dilatant models
//! The above is for a model that is [`Material::isochoric`] (elasticity, Tresca): its deviator
//! ignores the mean stress and its plastic flow keeps the volume, so the element may take the
//! deviator alone and close the pressure with the elastic volume law. A frictional model
//! (Mohr–Coulomb, Drucker–Prager) needs the pressure for its strength and changes volume as it
//! flows. For it the material returns its full stress σ_m (pressure p_m = −tr σ_m/3 included, a
//! dilatant return changing it), the momentum balance takes dev σ_m and the field p as above,
//! and the volume equation makes p the L2 projection of the material's pressure:
//! r_i = −∫_{Ω_n} L_i (p − p_m(ε)) / K dV.
//! For an elastic or isochoric state p_m = p_n − K ln J, so this is the equation above with
//! ln J for J − 1 (the two agree to O((J − 1)²)), and the element stays free of volumetric
//! locking as before: the K-sized volumetric stiffness enters only through the weakly enforced
//! P1 relation, never pointwise. Plastic volume change enters through p_m: a point that dilates
//! has p_m below its elastic value and the projection lets the P1 volume follow. A uniform
//! state has p = p_m exactly, so a block's stress is the material's to round-off. Its
//! derivative: ∂r_i/∂H = ∫ L_i (∂p_m/∂ε)(∂ε/∂H) / K, which is −(K_up)ᵀ only up to a factor J
//! and the model's pressure–deviator coupling: non-symmetric, as the step's solvers assume for
//! any plastic scene. The stored stress is dev σ_m (rotated) − p I, as for the other models: the
//! pressure history is the field's, which keeps point-to-point noise in the P2 divergence out
//! of the next step's strength.
//!
//! # Conditioning
//! Displacement and pressure rows have different units: K_uu ~ G, K_up ~ h (element size),
//! K_pp ~ h²/K. [`MixedOutput::with_pressure_scale`] with α = G/h (any representative G and h
//! of the mesh) rescales the pressure unknown to π = p/α, which has the units and the magnitude
//! of a displacement, and the pressure rows to force units, keeping the saddle point symmetric.

use crate::fem::analysis::{hoop_gradient, Analysis};
use crate::fem::element::{displacement_gradient, green_lagrange, ElementError, N_GAUSS};
use crate::fem::p2::{self, N_NODES};
use crate::fem::quadrature::{area_to_reference, TRI3_POINTS, TRI3_WEIGHTS};
use crate::material::layout::for_each_strain;
use crate::material::{GaussState, Material, MaterialError};

/// Displacement dofs per element (2 per P2 node).
pub const N_U_DOFS: usize = 2 * N_NODES;
/// Pressure dofs per element (one per vertex).
pub const N_P_DOFS: usize = 3;
/// Total dofs per element: displacements first, then pressures.
pub const N_MIXED_DOFS: usize = N_U_DOFS + N_P_DOFS;

type Mat2 = [[f64; 2]; 2];

/// Element contributions for one Newton iterate of the mixed element.
#[derive(Clone, Debug, PartialEq)]
pub struct MixedOutput {
    /// [momentum residual (12); volume residual (3)], see the module docs.
    pub residual: [f64; N_MIXED_DOFS],
    /// d residual / d [Δu (12); p (3)].
    pub tangent: [[f64; N_MIXED_DOFS]; N_MIXED_DOFS],
    /// Updated Gauss states; `stress` is the full end-of-step Cauchy stress σ_{n+1}, including
    /// −p from the interpolated pressure field.
    pub states: [GaussState; N_GAUSS],
}

impl MixedOutput {
    /// Re-expresses the element in the scaled pressure unknown π = p/α: pressure rows and
    /// pressure columns are multiplied by α (the pressure–pressure block by α²), which keeps the
    /// matrix symmetric where it was. With α = G/h the pressure unknown has the size of a
    /// displacement and all blocks scale like G; an assembler must use the same α everywhere
    /// and pass p = α π back to [`p2p1_element`].
    pub fn with_pressure_scale(mut self, alpha: f64) -> Self {
        for k in N_U_DOFS..N_MIXED_DOFS {
            self.residual[k] *= alpha;
            self.tangent[k].iter_mut().for_each(|v| *v *= alpha);
        }
        for row in self.tangent.iter_mut() {
            row[N_U_DOFS..].iter_mut().for_each(|v| *v *= alpha);
        }
        self
    }
}

/// atanh(x)/x and its derivative divided by x, for 0 ≤ x < 1, accurate near 0.
///
/// These are the scalar functions in the closed-form logarithm of a 2×2 SPD matrix: with
/// eigenvalues m ± r, ln of the matrix is ½ ln(det) I + (atanh(r/m)/r) (A − m I).
fn atanh_ratio(x: f64) -> (f64, f64) {
    if x < 0.2 {
        // Series g = Σ x^{2k}/(2k+1), h = g'/x = Σ_{k≥1} 2k x^{2k−2}/(2k+1); x² < 0.04, so the
        // first omitted term is below 0.04^14 ≈ 3e-20.
        let x2 = x * x;
        let mut g = 0.0;
        let mut h = 0.0;
        let mut pow = 1.0; // x^{2k}
        for k in 0..14 {
            let kf = f64::from(k);
            g += pow / (2.0 * kf + 1.0);
            h += 2.0 * (kf + 1.0) * pow / (2.0 * kf + 3.0);
            pow *= x2;
        }
        (g, h)
    } else {
        let g = x.atanh() / x;
        (g, (1.0 / (1.0 - x * x) - g) / (x * x))
    }
}

/// Kinematic quantities of one Gauss point and their derivatives with respect to H.
/// Derivative arrays are indexed by 2j + l for H_jl = ∂Δu_j/∂x_l.
/// Index 4 of the derivative arrays is the hoop gradient h_θ = Δu_r/r (axisymmetry).
struct StepKinematics {
    /// J = det F, the hoop stretch included, and J − 1.
    j: f64,
    jm1: f64,
    /// The in-plane F⁻¹.
    finv: Mat2,
    rot: Mat2,
    dtheta: [f64; 5],
    /// F_θθ = 1 + h_θ (1 in plane strain).
    f_hoop: f64,
    /// ε = ln U, Voigt `[xx, yy, zz, xy]`, engineering shear; ε_zz = ln F_θθ.
    eps: [f64; 4],
    deps: [[f64; 4]; 5],
}

/// Everything derived from H and the hoop gradient `h_hoop` (0 in plane strain); `Err(J)` if
/// the step inverts the material (J ≤ 0 or not finite) or is so close to it that C = FᵀF is
/// numerically singular (x rounds to 1, J ≈ 0).
fn step_kinematics(h: &Mat2, h_hoop: f64) -> Result<StepKinematics, f64> {
    // J − 1 kept separate so that tiny steps keep full relative precision in ln J and J − 1.
    let jm1_plane = h[0][0] + h[1][1] + (h[0][0] * h[1][1] - h[0][1] * h[1][0]);
    let j_plane = 1.0 + jm1_plane;
    let f_hoop = 1.0 + h_hoop;
    let jm1 = jm1_plane + h_hoop + jm1_plane * h_hoop;
    let j = 1.0 + jm1;
    if !(j.is_finite() && j > 0.0 && j_plane > 0.0 && f_hoop > 0.0) {
        return Err(j);
    }
    let j = j_plane * f_hoop;
    let f = [[1.0 + h[0][0], h[0][1]], [h[1][0], 1.0 + h[1][1]]];
    let finv = [
        [f[1][1] / j_plane, -f[0][1] / j_plane],
        [-f[1][0] / j_plane, f[0][0] / j_plane],
    ];

    // 2-D polar rotation: R = rot(θ), tan θ = (F10 − F01)/(F00 + F11); the pair cannot vanish
    // when det F > 0.
    let a = 2.0 + h[0][0] + h[1][1];
    let b = h[1][0] - h[0][1];
    let (sn, cs) = b.atan2(a).sin_cos();
    let rot = [[cs, -sn], [sn, cs]];
    let ab2 = a * a + b * b;
    let dtheta = [-b / ab2, -a / ab2, a / ab2, -b / ab2, 0.0];

    // ε = ½ ln C, C = I + 2E: eigenvalues of C are m_C ± 2ρ with m_C = 1 + tr E and ρ the
    // eigenvalue of dev E, so ε = ½ ln J I + (g(x)/m) dev E with x = 2ρ/m (< 1 as C is SPD).
    let e = green_lagrange(h);
    let m = 1.0 + e[0] + e[1];
    let dd = 0.5 * (e[0] - e[1]);
    let de = 0.5 * e[3];
    let x = 2.0 * dd.hypot(de) / m;
    if x.is_nan() || x >= 1.0 {
        return Err(j);
    }
    let (g, hh) = atanh_ratio(x);
    let phi = g / m;
    let half_ln_j = 0.5 * jm1_plane.ln_1p();
    let eps = [
        half_ln_j + phi * dd,
        half_ln_j - phi * dd,
        h_hoop.ln_1p(),
        2.0 * phi * de,
    ];

    let mut deps = [[0.0; 4]; 5];
    deps[4][2] = 1.0 / f_hoop;
    for (jl, dep) in deps.iter_mut().take(4).enumerate() {
        let (jj, l) = (jl / 2, jl % 2);
        // ∂E_ik/∂H_jl = ½ (δ_il F_jk + δ_kl F_ji), and ∂ln J/∂H_jl = (F⁻¹)_lj (in-plane J).
        let d_e00 = if l == 0 { f[jj][0] } else { 0.0 };
        let d_e11 = if l == 1 { f[jj][1] } else { 0.0 };
        let d_e01 = 0.5 * if l == 0 { f[jj][1] } else { f[jj][0] };
        let d_half_ln_j = 0.5 * finv[l][jj];
        let d_dd = 0.5 * (d_e00 - d_e11);
        let d_m = d_e00 + d_e11;
        // d(g/m): g' dx/m − g dm/m², with g'(x) dx written through h = g'/x so that nothing
        // divides by ρ (which vanishes for isotropic steps).
        let d_phi =
            4.0 * hh * (dd * d_dd + de * d_e01) / (m * m * m) - (x * x * hh + g) * d_m / (m * m);
        *dep = [
            d_half_ln_j + phi * d_dd + dd * d_phi,
            d_half_ln_j - phi * d_dd - dd * d_phi,
            0.0,
            2.0 * (phi * d_e01 + de * d_phi),
        ];
    }
    Ok(StepKinematics {
        j,
        jm1,
        finv,
        rot,
        dtheta,
        f_hoop,
        eps,
        deps,
    })
}

/// Logarithmic step strain ε = ln U = ½ ln(FᵀF) of F = I + H, Voigt `[xx, yy, zz, xy]` with
/// engineering shear, in the start-of-step frame; `None` if det F ≤ 0.
pub fn log_strain(h: &Mat2) -> Option<[f64; 4]> {
    step_kinematics(h, 0.0).ok().map(|k| k.eps)
}

/// Rotation R of the polar decomposition F = R U of F = I + H; `None` if det F ≤ 0.
pub fn step_rotation(h: &Mat2) -> Option<Mat2> {
    step_kinematics(h, 0.0).ok().map(|k| k.rot)
}

fn mul(a: &Mat2, b: &Mat2) -> Mat2 {
    let mut c = [[0.0; 2]; 2];
    for (ci, ai) in c.iter_mut().zip(a.iter()) {
        for (k, cik) in ci.iter_mut().enumerate() {
            *cik = ai[0] * b[0][k] + ai[1] * b[1][k];
        }
    }
    c
}

/// R A Rᵀ.
fn rotate(r: &Mat2, a: &Mat2) -> Mat2 {
    let ra = mul(r, a);
    let rt = [[r[0][0], r[1][0]], [r[0][1], r[1][1]]];
    mul(&ra, &rt)
}

/// In-plane tensor of a Voigt vector with tensor shear.
fn sym(v: &[f64; 4]) -> Mat2 {
    [[v[0], v[3]], [v[3], v[1]]]
}

fn invalid_bulk(bulk: f64) -> ElementError {
    ElementError::Material {
        gauss: 0,
        source: MaterialError::InvalidParameter {
            name: "bulk",
            value: bulk,
            requirement: "0 < bulk <= inf",
        },
    }
}

/// Residual, consistent tangent and updated states of the mixed P2–P1 element for one Newton
/// iterate; see the module docs for the formulation.
///
/// - `x`: start-of-step node positions x_n (P2 order);
/// - `du`: step displacements of the nodes;
/// - `p`: end-of-step Cauchy pressure (compression positive) at the three vertices;
/// - `states_n`: Gauss states at x_n (Cauchy σ_n; p_n = −tr σ_n/3 is taken from them);
/// - `mat`: supplies the deviatoric response through [`Material::update_log_strain`];
/// - `bulk`: bulk modulus K of the volume constraint, in (0, ∞]; pass the material's K for
///   its compressible response (e.g. [`crate::material::tresca::Tresca::bulk_modulus`]) or
///   `f64::INFINITY` for exact incompressibility. An invalid value is reported as
///   [`ElementError::Material`] (Gauss point 0) wrapping an `InvalidParameter` named `bulk`;
/// - `body_force`: force per unit volume of Ω_n;
/// - `analysis`: plane strain, or axisymmetry with the hoop terms of the module docs.
#[allow(clippy::too_many_arguments)]
pub fn p2p1_element(
    x: &[[f64; 2]; N_NODES],
    du: &[[f64; 2]; N_NODES],
    p: &[f64; N_P_DOFS],
    states_n: &[GaussState; N_GAUSS],
    mat: &dyn Material,
    bulk: f64,
    body_force: [f64; 2],
    analysis: Analysis,
) -> Result<MixedOutput, ElementError> {
    // A model that is not isochoric takes K as the scale of its projected pressure, which
    // must then be finite.
    let isochoric = mat.isochoric();
    if bulk.is_nan() || bulk <= 0.0 || (!isochoric && bulk.is_infinite()) {
        return Err(invalid_bulk(bulk));
    }
    let inv_k = 1.0 / bulk;
    let mut residual = [0.0; N_MIXED_DOFS];
    let mut tangent = [[0.0; N_MIXED_DOFS]; N_MIXED_DOFS];
    let mut states = states_n.clone();

    for q in 0..N_GAUSS {
        let lp = TRI3_POINTS[q]; // P1 pressure shape functions = area coordinates
        let xi = area_to_reference(lp);
        let pg = p2::physical_gradients(x, xi).map_err(|e| ElementError::DegenerateGeometry {
            gauss: q,
            det_j: e.det_j,
        })?;
        let n = p2::shape(xi);
        let hoop = analysis.has_hoop();
        // The radius and the hoop only where there is a hoop: assembly's hot path.
        let (radius, h_hoop) = if hoop {
            let radius = p2::map_to_physical(x, xi)[0];
            let ur: f64 = n.iter().zip(du).map(|(na, ua)| na * ua[0]).sum();
            (radius, hoop_gradient(analysis, radius, ur))
        } else {
            (1.0, 0.0)
        };
        let w = TRI3_WEIGHTS[q] * pg.det_j * analysis.measure(radius);
        let gx = &pg.grad;

        let h = displacement_gradient(gx, du);
        let kin =
            step_kinematics(&h, h_hoop).map_err(|j| ElementError::Inverted { gauss: q, j })?;
        let j = kin.j;
        let r = &kin.rot;
        // ∂h_θ/∂u_{b,r} = N_b / r: the hoop's share of the radial columns (0 in plane strain).
        let hoop_shape: [f64; N_NODES] =
            std::array::from_fn(|a| if hoop { n[a] / radius } else { 0.0 });

        // A stiffness that varies from point to point (`young_over_cu`) varies K too.
        let inv_k = mat.bulk_at(&states_n[q]).map_or(inv_k, |k| 1.0 / k);
        let p_h = lp[0] * p[0] + lp[1] * p[1] + lp[2] * p[2];
        let sn = &states_n[q].stress;
        let p_n = -(sn[0] + sn[1] + sn[2]) / 3.0;

        let resp = mat
            .update_log_strain(&states_n[q], &kin.eps)
            .map_err(|source| ElementError::Material { gauss: q, source })?;
        // Deviatoric parts of the response: the pressure comes from the p field instead.
        let mean = (resp.s[0] + resp.s[1] + resp.s[2]) / 3.0;
        let s_dev = [
            resp.s[0] - mean,
            resp.s[1] - mean,
            resp.s[2] - mean,
            resp.s[3],
        ];
        let mut d_dev = resp.d;
        for col in 0..4 {
            let m = (resp.d[0][col] + resp.d[1][col] + resp.d[2][col]) / 3.0;
            for row in d_dev.iter_mut().take(3) {
                row[col] -= m;
            }
        }

        let s_hat = sym(&s_dev);
        let rs = rotate(r, &s_hat);
        let sigma = [[rs[0][0] - p_h, rs[0][1]], [rs[1][0], rs[1][1] - p_h]];
        let tau = sigma.map(|row| row.map(|v| j * v));

        // Spatial gradients ∇_x N_a = F⁻ᵀ ∇_X N_a.
        let mut gs = [[0.0; 2]; N_NODES];
        for (ga, g0) in gs.iter_mut().zip(gx.iter()) {
            for (i, gai) in ga.iter_mut().enumerate() {
                *gai = kin.finv[0][i] * g0[0] + kin.finv[1][i] * g0[1];
            }
        }

        // τ_θθ/F_θθ = P_θθ, the hoop's first Piola stress: its virtual work is P_θθ δh_θ.
        let tau_hoop = j * (s_dev[2] - p_h);
        let p_hoop = tau_hoop / kin.f_hoop;
        for (a, ga) in gs.iter().enumerate() {
            for i in 0..2 {
                let f = tau[i][0] * ga[0] + tau[i][1] * ga[1];
                residual[2 * a + i] += w * (f - n[a] * body_force[i]);
            }
            residual[2 * a] += w * p_hoop * hoop_shape[a];
        }
        let vol = if isochoric {
            kin.jm1 + (p_h - p_n) * inv_k
        } else {
            (p_h + (resp.s[0] + resp.s[1] + resp.s[2]) / 3.0) * inv_k
        };
        // ∂p_m/∂H_jl = −⅓ tr(D ∂ε/∂H_jl), for the volume rows of a model that is not isochoric.
        let mut dpm = [0.0; 5];
        if !isochoric {
            for (dp, de) in dpm.iter_mut().zip(&kin.deps) {
                *dp = -(0..3)
                    .map(|r| (0..4).map(|c| resp.d[r][c] * de[c]).sum::<f64>())
                    .sum::<f64>()
                    / 3.0;
            }
        }
        for (i, li) in lp.iter().enumerate() {
            residual[N_U_DOFS + i] -= w * li * vol;
        }

        // dτ/dH_jl = (∂J/∂H_jl) σ + J [R (W ŝ − ŝ W) Rᵀ ∂θ/∂H_jl + R (∂ŝ/∂H_jl) Rᵀ],
        // W = [[0, −1], [1, 0]] the generator of dR = R W dθ, and ∂J/∂H_jl = J (F⁻¹)_lj.
        let comm = [
            [-2.0 * s_hat[0][1], s_hat[0][0] - s_hat[1][1]],
            [s_hat[0][0] - s_hat[1][1], 2.0 * s_hat[0][1]],
        ];
        let rcomm = rotate(r, &comm);
        // In-plane dτ and the hoop's dτ_θθ per H_jl, index 4 the hoop gradient h_θ.
        let mut dtau = [[[0.0; 2]; 2]; 5];
        let mut dtau_hoop = [0.0; 5];
        for (jl, dt) in dtau.iter_mut().enumerate().take(if hoop { 5 } else { 4 }) {
            let mut ds = [0.0; 4];
            for (dsi, row) in ds.iter_mut().zip(d_dev.iter()) {
                *dsi = row
                    .iter()
                    .zip(kin.deps[jl].iter())
                    .map(|(a, b)| a * b)
                    .sum();
            }
            let rds = rotate(r, &sym(&ds));
            let dj = if jl < 4 {
                j * kin.finv[jl % 2][jl / 2]
            } else {
                j / kin.f_hoop
            };
            for i in 0..2 {
                for k in 0..2 {
                    dt[i][k] = dj * sigma[i][k] + j * (rcomm[i][k] * kin.dtheta[jl] + rds[i][k]);
                }
            }
            dtau_hoop[jl] = dj * (s_dev[2] - p_h) + j * ds[2];
        }

        // K_(a,i),(b,jj) = w [ Σ_l (dτ/dH_{jj,l} ∇_x N_a)_i ∂N_b/∂X_l − (τ ∇_x N_b)_i (∇_x N_a)_jj ]
        for (bn, gb0) in gx.iter().enumerate() {
            let tgb = [
                tau[0][0] * gs[bn][0] + tau[0][1] * gs[bn][1],
                tau[1][0] * gs[bn][0] + tau[1][1] * gs[bn][1],
            ];
            for jj in 0..2 {
                // The hoop gradient moves with the radial component only.
                let hb = if jj == 0 { hoop_shape[bn] } else { 0.0 };
                let mut mjb = [[0.0; 2]; 2];
                for (l, gbl) in gb0.iter().enumerate() {
                    for i in 0..2 {
                        for k in 0..2 {
                            mjb[i][k] += dtau[2 * jj + l][i][k] * gbl;
                        }
                    }
                }
                let mut dp_hoop = 0.0;
                if hoop {
                    for i in 0..2 {
                        for k in 0..2 {
                            mjb[i][k] += dtau[4][i][k] * hb;
                        }
                    }
                    dp_hoop = (dtau_hoop[2 * jj] * gb0[0] + dtau_hoop[2 * jj + 1] * gb0[1])
                        / kin.f_hoop
                        + hb * (dtau_hoop[4] - p_hoop) / kin.f_hoop;
                }
                let col = 2 * bn + jj;
                for (a, ga) in gs.iter().enumerate() {
                    for i in 0..2 {
                        let v = mjb[i][0] * ga[0] + mjb[i][1] * ga[1] - tgb[i] * ga[jj];
                        tangent[2 * a + i][col] += w * v;
                    }
                    tangent[2 * a][col] += w * hoop_shape[a] * dp_hoop;
                }
                // K_up[(b, jj)][m] = −w J L_m ((∇_x N_b)_jj + δ_jj0 N_b/(r F_θθ)), which is
                // ∂J/∂u_(b,jj) times −w L_m; for an isochoric model K_pu is its exact transpose.
                let dpm_b = dpm[2 * jj] * gb0[0] + dpm[2 * jj + 1] * gb0[1] + dpm[4] * hb;
                let dj_b = gs[bn][jj] + hb / kin.f_hoop;
                for (m, lm) in lp.iter().enumerate() {
                    let c = -w * j * lm * dj_b;
                    tangent[col][N_U_DOFS + m] += c;
                    tangent[N_U_DOFS + m][col] +=
                        if isochoric { c } else { w * lm * dpm_b * inv_k };
                }
            }
        }
        for (m, lm) in lp.iter().enumerate() {
            for (nn, ln) in lp.iter().enumerate() {
                tangent[N_U_DOFS + m][N_U_DOFS + nn] -= w * lm * ln * inv_k;
            }
        }

        let mut st = resp.state;
        st.stress = [sigma[0][0], sigma[1][1], s_dev[2] - p_h, sigma[0][1]];
        // Strain-like internal variables were computed in the rotation-free frame, as the stress.
        for_each_strain(mat.internal_variables(), &mut st.internal, |ep| {
            let rep = rotate(r, &[[ep[0], 0.5 * ep[3]], [0.5 * ep[3], ep[1]]]);
            ep[0] = rep[0][0];
            ep[1] = rep[1][1];
            ep[3] = 2.0 * rep[0][1];
        });
        states[q] = st;
    }

    Ok(MixedOutput {
        residual,
        tangent,
        states,
    })
}

#[cfg(test)]
// Index loops mirror the component notation of the formulas being checked.
#[allow(clippy::needless_range_loop)]
mod tests;
