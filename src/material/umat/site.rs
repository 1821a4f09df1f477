//! Where and when a model is called: the increment (KSTEP, KINC, TIME, DTIME) and the element
//! (NOEL, NPT, COORDS, CELENT). The [`crate::material::Material`] interface hands a model only
//! the state and the strain; the step loop and the assembler note the rest here, per thread,
//! so that neither the interface nor the elements change for the models that read them: a UMAT
//! (all of it), and `tresca-softening` (the step's duration for its rate factor, the element's
//! size for its regularised ξ95). The solve is single-threaded per rank, so a thread-local note
//! is the rank's, and material code needs no MPI.

use std::cell::Cell;

/// The increment being solved. Its time is the scene's time in seconds when the scene gives
/// one (`steps.duration`, or a `duration`/`velocity` on the `[[rigid]]` stages), else the load
/// factor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Increment {
    /// KINC: the step number (1-based); a cut step keeps its number.
    pub step: i32,
    /// TIME(1) = TIME(2): the time at the start of the increment (s), or its load factor.
    pub time: f64,
    /// DTIME: the increment's duration (s), or its load-factor increment.
    pub dtime: f64,
    /// Whether `time` and `dtime` are seconds (the scene gives a duration).
    pub real: bool,
}

/// The element being evaluated, at the start of the step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Element {
    /// NOEL: the triangle's local index + 1 (rank-local; PFEM remeshes every step).
    pub number: i32,
    /// The Gauss points' positions, in the element's Gauss point order.
    pub gauss: [[f64; 2]; 3],
    /// CELENT: √(2 × area), the side of the right isosceles triangle of the same area.
    pub size: f64,
}

thread_local! {
    static INCREMENT: Cell<Increment> = const {
        Cell::new(Increment { step: 1, time: 0.0, dtime: 1.0, real: false })
    };
    static ELEMENT: Cell<Option<Element>> = const { Cell::new(None) };
    /// Calls since the element was noted: the elements call their model once per Gauss point,
    /// in order, so the count is NPT.
    static CALLS: Cell<usize> = const { Cell::new(0) };
}

/// Notes the increment from load factor `from` to `to` of step `step`; `seconds`: the scene's
/// time (s) at `from` and at `to`, when it gives one.
pub fn set_increment(step: u64, from: f64, to: f64, seconds: Option<[f64; 2]>) {
    let step = i32::try_from(step).unwrap_or(i32::MAX);
    let ([t0, t1], real) = match seconds {
        Some(t) => (t, true),
        None => ([from, to], false),
    };
    INCREMENT.set(Increment {
        step,
        time: t0,
        dtime: t1 - t0,
        real,
    });
}

/// The duration (s) of the increment being solved, when the scene gives time.
pub fn step_seconds() -> Option<f64> {
    let inc = INCREMENT.get();
    inc.real.then_some(inc.dtime)
}

/// The size (CELENT, m) of the element being evaluated, None outside an element evaluation.
/// Unlike [`take_call`] it does not count a call.
pub fn element_size() -> Option<f64> {
    ELEMENT.get().map(|e| e.size)
}

/// Forgets the element (for callers that evaluate a model outside the assembly, and tests).
pub fn clear_element() {
    ELEMENT.set(None);
}

/// Notes the element about to be evaluated: local triangle `t` with straight-sided P2 nodes
/// `x` (corners first) at the start of the step.
pub fn set_element(t: usize, x: &[[f64; 2]; 6]) {
    let [a, b, c] = [x[0], x[1], x[2]];
    let area = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])).abs();
    // The 3-point rule's points, area coordinates (2/3, 1/6, 1/6) and permutations.
    let at = |l: [f64; 3]| {
        [
            l[0] * a[0] + l[1] * b[0] + l[2] * c[0],
            l[0] * a[1] + l[1] * b[1] + l[2] * c[1],
        ]
    };
    let gauss = crate::fem::quadrature::TRI3_POINTS.map(at);
    ELEMENT.set(Some(Element {
        number: i32::try_from(t + 1).unwrap_or(i32::MAX),
        gauss,
        size: (2.0 * area).sqrt(),
    }));
    CALLS.set(0);
}

/// The increment, and the element with the 0-based Gauss point of this call (None outside an
/// element evaluation); counts the call.
pub fn take_call() -> (Increment, Option<(Element, usize)>) {
    let n = CALLS.get();
    CALLS.set(n + 1);
    let e = ELEMENT.get().map(|e| (e, n % 3));
    (INCREMENT.get(), e)
}
