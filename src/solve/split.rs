//! The two fields of the mixed P2–P1 system for a Schur-complement preconditioner: which global
//! dofs are displacements and which pressures, the pressures' own numbering (the layout of the
//! Schur complement), and the pressure mass matrix scaled by the inverse shear modulus that
//! stands in for the Schur complement.

use super::DofMap;
use crate::fem::element::displacement_gradient;
use crate::fem::mixed::log_strain;
use crate::fem::p2::physical_gradients;
use crate::fem::quadrature::{area_to_reference, TRI3_POINTS};
use crate::material::{GaussState, Material};
use mpi::traits::Communicator;
use pfem_partition::{exscan_u64, fetch_pairs, sum_f64, Comm, PartitionError};

/// The owned dofs of each field and the pressure numbering.
pub struct FieldLayout {
    /// Global dofs of this rank's displacement unknowns, node by node (ux, uy).
    pub displacement: Vec<usize>,
    /// Global dofs of this rank's pressure unknowns.
    pub pressure: Vec<usize>,
    /// Per local pressure unknown ([`DofMap::pressure_unknown`]): its index in the
    /// pressure-only numbering.
    pub pressure_index: Vec<usize>,
    /// Nonzeros per owned pressure row of the P1 mass matrix, in and out of the diagonal block.
    pub mass_d_nnz: Vec<usize>,
    pub mass_o_nnz: Vec<usize>,
}

impl FieldLayout {
    /// Collective. The layout of a mixed `dofs` (vertex nodes carry ux, uy and pressures).
    pub fn new(comm: &Comm, dofs: &DofMap) -> Result<FieldLayout, PartitionError> {
        assert_eq!(dofs.vertex_dofs, 3, "a field split needs pressure unknowns");
        let mut displacement = Vec::new();
        let mut pressure = Vec::new();
        for n in 0..dofs.n_nodes() {
            if dofs.node_owned[n] {
                let g = dofs.node_global[n];
                displacement.extend([g, g + 1]);
                pressure.extend((2..dofs.ndof(n)).map(|c| g + c));
            }
        }
        let (first_p, _) = exscan_u64(comm, pressure.len() as u64);
        let size = comm.size() as usize;
        let mut slots = vec![0.0; 2 * size];
        slots[2 * comm.rank() as usize] = dofs.first_dof as f64;
        slots[2 * comm.rank() as usize + 1] = first_p as f64;
        let firsts = sum_f64(comm, &slots);
        let first_dof: Vec<usize> = (0..size).map(|r| firsts[2 * r] as usize).collect();
        let first_pressure: Vec<usize> = (0..size).map(|r| firsts[2 * r + 1] as usize).collect();
        // The owner of global dof g: the last rank whose first dof is at or below g (ranks
        // without dofs share their successor's first dof and come before it).
        let owner = |g: usize| first_dof.partition_point(|&f| f <= g) - 1;
        let n_vertex = dofs.n_nodes() - dofs.edges.len();
        let pressure_index = if dofs.material_pressures.is_none() {
            // A rank numbers its owned vertex nodes first (3 dofs each), so an owned vertex's
            // position among them is (g - first_dof) / 3 on its owner: with every rank's first
            // dof and first pressure, any rank numbers any vertex's pressure by itself.
            (0..n_vertex)
                .map(|n| {
                    let g = dofs.node_global[n];
                    let r = owner(g);
                    first_pressure[r] + (g - first_dof[r]) / 3
                })
                .collect()
        } else {
            // Vertices with several pressures break that count: a ghost pressure's index is
            // asked of its owner, which finds the dof among its own (increasing) pressures.
            let mut index = vec![usize::MAX; dofs.n_pressure_unknowns()];
            let mut requests = Vec::new();
            let mut asked = Vec::new();
            for n in 0..n_vertex {
                for c in 2..dofs.ndof(n) {
                    let g = dofs.global_dof(n, c);
                    let u = dofs.pressure_unknown(n, c);
                    requests.push((owner(g) as i32, [g as u64, 0]));
                    asked.push(u);
                }
            }
            let answers = fetch_pairs(comm, &requests, |k| {
                let at = pressure.binary_search(&(k[0] as usize)).map_err(|_| {
                    PartitionError::InvalidInput(format!(
                        "dof {} asked for as a pressure is not one of its owner's",
                        k[0]
                    ))
                })?;
                Ok((first_p as usize + at) as u64)
            })?;
            for (u, i) in asked.into_iter().zip(answers) {
                index[u] = i as usize;
            }
            index
        };
        let (mass_d_nnz, mass_o_nnz) = dofs.pressure_neighbour_counts().into_iter().unzip();
        Ok(FieldLayout {
            displacement,
            pressure,
            pressure_index,
            mass_d_nnz,
            mass_o_nnz,
        })
    }
}

/// The P1 mass matrix of a triangle of area `area`: ∫ L_i L_j = area (1 + δ_ij) / 12.
pub fn p1_mass(area: f64) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| area * if i == j { 2.0 } else { 1.0 } / 12.0))
}

/// The shear stiffness of the material's tangent over a triangle at the step displacement
/// `du`: at each Gauss point the mean of the tangent's stiffness against the two in-plane
/// deviatoric strains (a stretch and a shear), averaged over the points. It is G for an
/// elastic tangent, G/2 for a perfectly plastic continuum tangent at yield (one deviatoric
/// direction has lost its stiffness) and βG/2 for the consistent tangent of a radial return
/// (β = strength / trial stress), so the Schur preconditioner follows the tangent without
/// dividing by zero.
/// `None` when the triangle is inverted or degenerate at `du`.
pub fn effective_shear_modulus(
    x: &[[f64; 2]; 6],
    du: &[[f64; 2]; 6],
    states_n: &[GaussState; 3],
    material: &dyn Material,
) -> Option<f64> {
    let mut sum = 0.0;
    for (q, l) in TRI3_POINTS.iter().enumerate() {
        let pg = physical_gradients(x, area_to_reference(*l)).ok()?;
        let h = displacement_gradient(&pg.grad, du);
        let eps = log_strain(&h)?;
        let d = material.update_log_strain(&states_n[q], &eps).ok()?.d;
        // Stretch (1, -1)/√2: ε·Dε = 2G; engineering shear γ = 1: ε·Dε = G.
        let stretch = 0.25 * (d[0][0] - d[0][1] - d[1][0] + d[1][1]);
        let shear = d[3][3];
        sum += 0.5 * (stretch + shear);
    }
    Some(sum / TRI3_POINTS.len() as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::elastic::LinearElastic;
    use crate::material::tresca::Tresca;

    fn triangle() -> [[f64; 2]; 6] {
        crate::fem::p2::straight_sided(&[[0.0, 0.0], [1.0, 0.1], [0.2, 0.9]])
    }

    #[test]
    fn effective_shear_is_g_for_an_elastic_tangent() {
        let (e, nu) = (12.0e6, 0.3);
        let g = e / (2.0 * (1.0 + nu));
        let mat = LinearElastic::new(e, nu).expect("material");
        let states = <[GaussState; 3]>::default();
        let du = [[0.001, -0.002]; 6];
        let got = effective_shear_modulus(&triangle(), &du, &states, &mat).expect("valid");
        assert!((got - g).abs() < 1e-9 * g, "{got} vs {g}");
    }

    #[test]
    fn effective_shear_follows_the_consistent_plastic_tangent() {
        let (e, nu, cu) = (10.0e6, 0.49, 10.0e3);
        let g = e / (2.0 * (1.0 + nu));
        let mat = Tresca::new(e, nu, cu).expect("material");
        let states = <[GaussState; 3]>::default();
        // A simple shear well past yield: γ = 0.01 ≫ cu/G.
        let x = triangle();
        let du: [[f64; 2]; 6] = std::array::from_fn(|k| [0.01 * x[k][1], 0.0]);
        let got = effective_shear_modulus(&x, &du, &states, &mat).expect("valid");
        // Radial return from the trial shear stress Gγ to cu: β = cu / (Gγ), and the
        // remaining deviatoric direction keeps βG; the log strain moves it by O(γ²).
        let beta = cu / (g * 0.01);
        let want = 0.5 * beta * g;
        assert!((got - want).abs() < 1e-4 * want, "{got} vs {want}");
        assert!(got < 0.5 * g);
    }

    #[test]
    fn p1_mass_sums_to_the_area() {
        let m = p1_mass(0.3);
        let total: f64 = m.iter().flatten().sum();
        assert!((total - 0.3).abs() < 1e-15);
    }
}
