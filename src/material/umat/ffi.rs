//! The one place where pfem-mpi calls into a user's UMAT library: opening it, finding `umat_`,
//! and calling it with Fortran's conventions. Everything unsafe about plug-ins is here, behind
//! [`Library::open`] and [`Library::call`].

use std::path::{Path, PathBuf};

/// Length Abaqus gives CMNAME (CHARACTER*80).
const CMNAME_LEN: usize = 80;

/// gfortran's (and ifort's) name for `SUBROUTINE UMAT`: lower case with a trailing underscore.
const SYMBOL: &[u8] = b"umat_";

/// The Abaqus UMAT interface, every argument by reference; the last one is the hidden length
/// of CMNAME that Fortran compilers append for a CHARACTER argument (a `size_t` since gfortran 8).
type UmatFn = unsafe extern "C" fn(
    stress: *mut f64,
    statev: *mut f64,
    ddsdde: *mut f64,
    sse: *mut f64,
    spd: *mut f64,
    scd: *mut f64,
    rpl: *mut f64,
    ddsddt: *mut f64,
    drplde: *mut f64,
    drpldt: *mut f64,
    stran: *const f64,
    dstran: *const f64,
    time: *const f64,
    dtime: *const f64,
    temp: *const f64,
    dtemp: *const f64,
    predef: *const f64,
    dpred: *const f64,
    cmname: *const u8,
    ndi: *const i32,
    nshr: *const i32,
    ntens: *const i32,
    nstatv: *const i32,
    props: *const f64,
    nprops: *const i32,
    coords: *const f64,
    drot: *const f64,
    pnewdt: *mut f64,
    celent: *const f64,
    dfgrd0: *const f64,
    dfgrd1: *const f64,
    noel: *const i32,
    npt: *const i32,
    layer: *const i32,
    kspt: *const i32,
    kstep: *const i32,
    kinc: *const i32,
    cmname_len: usize,
);

/// Everything a UMAT reads and writes at one Gauss point, laid out as Fortran expects it
/// (matrices column-major). `NTENS` is 4: plane strain, components 11, 22, 33, 12.
#[derive(Debug)]
pub struct Call<'a> {
    pub stress: [f64; 4],
    pub statev: &'a mut [f64],
    pub ddsdde: [f64; 16],
    pub sse: f64,
    pub spd: f64,
    pub scd: f64,
    pub stran: [f64; 4],
    pub dstran: [f64; 4],
    pub time: [f64; 2],
    pub dtime: f64,
    pub props: &'a [f64],
    pub coords: [f64; 3],
    pub drot: [f64; 9],
    pub pnewdt: f64,
    pub celent: f64,
    pub dfgrd0: [f64; 9],
    pub dfgrd1: [f64; 9],
    pub noel: i32,
    pub npt: i32,
    pub kstep: i32,
    pub kinc: i32,
}

/// An opened UMAT library. The symbol is looked up once; the library stays mapped as long as
/// this value lives, which is as long as the material model that owns it.
pub struct Library {
    path: PathBuf,
    umat: UmatFn,
    // Declared last so that it is dropped after `umat`, which points into it.
    _lib: libloading::Library,
}

impl std::fmt::Debug for Library {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "UMAT library {}", self.path.display())
    }
}

impl Library {
    /// Opens `path` and finds `umat_` in it; the error says which of the two failed.
    pub fn open(path: &Path) -> Result<Library, String> {
        if !path.is_file() {
            return Err(format!("no such file: {}", path.display()));
        }
        // SAFETY: loading runs the library's initialisers. A UMAT library is the user's own
        // code, trusted as much as a Fortran UMAT is in Abaqus; pfem-mpi calls nothing else in it.
        let lib = unsafe { libloading::Library::new(path) }
            .map_err(|e| format!("cannot load {}: {e}", path.display()))?;
        // SAFETY: the type is the Abaqus UMAT interface; a library whose `umat_` has another
        // signature is a user error that no loader can detect.
        let umat: UmatFn = unsafe { lib.get::<UmatFn>(SYMBOL) }
            .map(|s| *s)
            .map_err(|_| {
                format!(
                    "{} has no subroutine UMAT (symbol `umat_`, as gfortran names it)",
                    path.display()
                )
            })?;
        Ok(Library {
            path: path.to_path_buf(),
            umat,
            _lib: lib,
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Calls the UMAT once with `c`, which it updates in place.
    pub fn call(&self, c: &mut Call<'_>, cmname: &str) {
        let mut name = [b' '; CMNAME_LEN];
        for (d, s) in name.iter_mut().zip(cmname.bytes()) {
            *d = s;
        }
        let (ndi, nshr, ntens) = (3i32, 1i32, 4i32);
        let nstatv = c.statev.len() as i32;
        let nprops = c.props.len() as i32;
        let (layer, kspt) = (1i32, 1i32);
        // Thermal and field-variable arguments: pfem-mpi is isothermal, but a UMAT may write
        // them, so they are real, writable storage.
        let (mut rpl, mut ddsddt, mut drplde, mut drpldt) = (0.0, [0.0; 4], [0.0; 4], 0.0);
        let (temp, dtemp, predef, dpred) = (0.0, 0.0, [0.0; 1], [0.0; 1]);
        // A UMAT with no state variables or properties still gets a valid address.
        let mut no_statev = [0.0];
        let statev = if c.statev.is_empty() {
            no_statev.as_mut_ptr()
        } else {
            c.statev.as_mut_ptr()
        };
        let no_props = [0.0];
        let props = if c.props.is_empty() {
            no_props.as_ptr()
        } else {
            c.props.as_ptr()
        };
        // SAFETY: every pointer is to live storage of the size the Abaqus interface gives it for
        // NTENS = 4, NSTATV = statev.len(), NPROPS = props.len(); none is kept after the call.
        // The UMAT is Fortran: it cannot unwind into Rust.
        unsafe {
            (self.umat)(
                c.stress.as_mut_ptr(),
                statev,
                c.ddsdde.as_mut_ptr(),
                &mut c.sse,
                &mut c.spd,
                &mut c.scd,
                &mut rpl,
                ddsddt.as_mut_ptr(),
                drplde.as_mut_ptr(),
                &mut drpldt,
                c.stran.as_ptr(),
                c.dstran.as_ptr(),
                c.time.as_ptr(),
                &c.dtime,
                &temp,
                &dtemp,
                predef.as_ptr(),
                dpred.as_ptr(),
                name.as_ptr(),
                &ndi,
                &nshr,
                &ntens,
                &nstatv,
                props,
                &nprops,
                c.coords.as_ptr(),
                c.drot.as_ptr(),
                &mut c.pnewdt,
                &c.celent,
                c.dfgrd0.as_ptr(),
                c.dfgrd1.as_ptr(),
                &c.noel,
                &c.npt,
                &layer,
                &kspt,
                &c.kstep,
                &c.kinc,
                CMNAME_LEN,
            );
        }
    }
}
