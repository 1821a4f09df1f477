//! What a run leaves in its output folder: history.csv, ParaView fields, checkpoints.

use super::error::agree;
use super::{RunError, Simulation};
use crate::history::{self, HistoryFile};
use crate::material::{StateLayout, VarKind};
use crate::mesh::LocalMesh;
use crate::output::{Field, FieldsWriter, Frame};
use mpi::traits::Communicator;
use pfem_partition::Comm;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// history.csv and checkpoints under the run's output folder.
pub struct Output {
    dir: PathBuf,
    history: Option<HistoryFile>,
    fields: FieldsWriter,
}

/// `DIR/scene.toml`: the resolved scene of the run, which the plots read for the declared
/// columns' reference lines (written to a temporary name and renamed).
fn write_scene(dir: &Path, sim: &Simulation) -> Result<(), RunError> {
    let path = dir.join("scene.toml");
    crate::output::replace_file(&path, sim.scene().to_toml().as_bytes())
        .map_err(|message| RunError::Io { path, message })
}

/// Refuses a folder that holds another case's run: its checkpoints, history and fields would be
/// mixed with this one's, and pruning would delete the other run's checkpoints. The folder's
/// `scene.toml` tells: a continuation of the same case has the same scene.
fn check_same_case(dir: &Path, sim: &Simulation) -> Result<(), RunError> {
    let path = dir.join("scene.toml");
    let Ok(text) = std::fs::read_to_string(&path) else {
        return Ok(());
    };
    let dir = dir.to_path_buf();
    match crate::scene::Scene::from_toml(&text, &path.display().to_string(), &[]) {
        Ok(scene) if &scene == sim.scene() => Ok(()),
        Err(error) => Err(RunError::UnreadableOutput { dir, error }),
        Ok(_) => Err(RunError::OtherCase {
            dir,
            scene_file: path,
        }),
    }
}

impl Output {
    /// Collective. Creates `DIR` (rank 0) and opens the history, keeping rows of earlier runs up to
    /// the restart step. A `DIR` holding another case's run is refused.
    pub fn open(world: &Comm, sim: &Simulation, dir: &Path) -> Result<Output, RunError> {
        let mut local = None;
        let mut history = None;
        if world.rank() == 0 {
            match check_same_case(dir, sim)
                .and_then(|_| {
                    std::fs::create_dir_all(dir.join("checkpoints")).map_err(|e| RunError::Io {
                        path: dir.to_path_buf(),
                        message: e.to_string(),
                    })
                })
                .and_then(|_| write_scene(dir, sim))
                .and_then(|_| {
                    HistoryFile::open(dir, sim.scene(), sim.step()).map_err(RunError::History)
                }) {
                Ok(h) => history = Some(h),
                Err(e) => local = Some(e),
            }
        }
        agree(world, local)?;
        let fields = FieldsWriter::open(world, dir, sim.step())?;
        Ok(Output {
            dir: dir.to_path_buf(),
            history,
            fields,
        })
    }

    /// Collective. ParaView fields every `output.fields_every` steps and at the last step of the
    /// run: per particle displacement, step increment, ε_q^p, stresses, pressure and owning rank,
    /// on the mesh the step was solved on.
    pub fn fields_if_due(
        &mut self,
        world: &Comm,
        sim: &Simulation,
        mesh: &LocalMesh,
        last: u64,
    ) -> Result<(), RunError> {
        let every = sim.scene().output.fields_every as u64;
        let step = sim.step();
        if step != last && (every == 0 || !step.is_multiple_of(every)) {
            return Ok(());
        }
        let p = &sim.particles;
        let layout = sim.model.layout();
        let triangles: Vec<[u64; 3]> = (0..mesh.tris.len())
            .filter(|&t| mesh.tri_owned[t])
            .map(|t| mesh.tri_key(t))
            .collect();
        let owners: HashMap<u64, i32> = sim
            .ghosts
            .gid
            .iter()
            .copied()
            .zip(sim.ghosts.owner.iter().copied())
            .collect();
        let owner_of = |g: u64| owners.get(&g).copied();
        let frame = Frame {
            step,
            time: sim.load_factor(),
            gid: &p.gid,
            position: &p.position,
            point_data: point_data(world, p, &layout),
            triangles: &triangles,
            owner_of: &owner_of,
        };
        Ok(self.fields.write(world, &frame)?)
    }

    /// Collective. Rank 0 draws the run's pictures (`pfem-mpi plot DIR` redraws them).
    pub fn plot(&self, world: &Comm) -> Result<(), RunError> {
        let local = if world.rank() == 0 {
            crate::plot::plot_run(&self.dir).err().map(RunError::from)
        } else {
            None
        };
        agree(world, local)
    }

    /// Collective. Appends the step's row, and returns it (after `step`) on rank 0.
    pub fn record(&mut self, world: &Comm, sim: &Simulation) -> Result<Option<Vec<f64>>, RunError> {
        let m = sim.measures(world);
        let mut local = None;
        let mut row = None;
        if let Some(h) = self.history.as_mut() {
            match history::row(sim.scene(), &m).and_then(|r| h.append(sim.step(), &r).map(|_| r)) {
                Ok(r) => row = Some(r),
                Err(e) => local = Some(RunError::History(e)),
            }
        }
        agree(world, local)?;
        Ok(row)
    }

    /// Collective. Checkpoint every K steps (scene setting) and at the last step of the run.
    pub fn checkpoint_if_due(
        &mut self,
        world: &Comm,
        sim: &Simulation,
        last: u64,
    ) -> Result<(), RunError> {
        let every = sim.scene().output.checkpoint_every as u64;
        let step = sim.step();
        if step != last && (every == 0 || !step.is_multiple_of(every)) {
            return Ok(());
        }
        let path = self
            .dir
            .join("checkpoints")
            .join(format!("step_{step:06}.h5"));
        sim.write_checkpoint(world, &path)?;
        if world.rank() == 0 {
            prune_checkpoints(
                &self.dir.join("checkpoints"),
                sim.scene().output.checkpoint_keep as usize,
            );
        }
        Ok(())
    }
}

/// Keeps the newest `keep` checkpoints.
fn prune_checkpoints(dir: &Path, keep: usize) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut names: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("step_") && n.ends_with(".h5"))
        })
        .collect();
    names.sort();
    let n = names.len();
    for p in names.into_iter().take(n.saturating_sub(keep.max(1))) {
        let _ = std::fs::remove_file(p);
    }
}

/// The fields of a frame: displacements, the stress as the plots read it, then one field per
/// internal variable of the material's layout, by its name (a strain tensor as a tensor field).
/// `eps_q` is written for every law, zero for one that does not yield, so that every run has the
/// accumulated-plastic-strain picture.
fn point_data<'a>(
    world: &Comm,
    p: &'a crate::particles::Particles,
    layout: &StateLayout,
) -> Vec<Field<'a>> {
    let col = |k: usize| p.state.iter().map(|s| s[k]).collect::<Vec<f64>>();
    let mut out = vec![
        Field::VectorRef("displacement".into(), &p.displacement),
        Field::VectorRef("incremental_displacement".into(), &p.increment),
        Field::Scalar("sigma_xx".into(), col(0)),
        Field::Scalar("sigma_yy".into(), col(1)),
        // Out of the plane: σzz of plane strain, the hoop stress σθθ of axisymmetry.
        Field::Scalar("sigma_zz".into(), col(2)),
        Field::Scalar("tau_xy".into(), col(3)),
        Field::Scalar(
            "pressure".into(),
            p.state
                .iter()
                .map(|s| -(s[0] + s[1] + s[2]) / 3.0)
                .collect(),
        ),
        Field::Scalar("rank".into(), vec![world.rank() as f64; p.len()]),
        Field::Scalar(
            "material".into(),
            p.material.iter().map(|&m| f64::from(m)).collect(),
        ),
    ];
    if layout.find("eps_q").is_none() {
        out.push(Field::Scalar("eps_q".into(), vec![0.0; p.len()]));
    }
    for v in layout.vars() {
        let (at, kind) = layout.find(&v.name).expect("a declared variable");
        out.push(match kind {
            VarKind::Scalar => Field::Scalar(v.name.clone(), col(at)),
            VarKind::Strain => Field::Tensor(
                v.name.clone(),
                p.state
                    .iter()
                    .map(|s| [s[at], s[at + 1], s[at + 2], 0.5 * s[at + 3]])
                    .collect(),
            ),
        });
    }
    out
}
