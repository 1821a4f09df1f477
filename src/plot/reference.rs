//! Reference solutions drawn with the results (`docs/reference.md`).

use std::f64::consts::PI;

/// Inextensible elastica of the end-loaded cantilever (Bisshopp–Drucker): λ = P L²/(E I), tip
/// shortening u/L and tip deflection v/L, with the unloaded beam first.
pub(crate) const ELASTICA: [[f64; 3]; 11] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.05643, 0.30172],
    [2.0, 0.16064, 0.49346],
    [3.0, 0.25442, 0.60325],
    [4.0, 0.32894, 0.66996],
    [5.0, 0.38763, 0.71379],
    [6.0, 0.43459, 0.74457],
    [7.0, 0.47293, 0.76737],
    [8.0, 0.50483, 0.78498],
    [9.0, 0.53182, 0.79906],
    [10.0, 0.55500, 0.81061],
];

/// Shear-deformable, extensible (Reissner) beam with the plane-strain modulus: the values a
/// converged plane-strain continuum should approach, as [λ, u/L, v/L].
pub(crate) const REISSNER: [[f64; 3]; 3] = [
    [2.0, 0.153, 0.485],
    [5.0, 0.378, 0.713],
    [10.0, 0.548, 0.8175],
];

/// Prandtl's bearing capacity of a surface strip on Tresca clay, q/cu.
pub(crate) const PRANDTL: f64 = 2.0 + PI;

/// Deep limit of a smooth strip in full flow, q/cu; the footing curve must stay below it.
pub(crate) const DEEP_STRIP: f64 = 2.0 + 2.0 * PI;

/// Unconfined compressive strength of Tresca material, stress/cu.
pub(crate) const TRESCA_COMPRESSION: f64 = 2.0;

/// Volume ratio of an isochoric (incompressible) deformation.
pub(crate) const ISOCHORIC: f64 = 1.0;
