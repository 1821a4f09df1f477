//! Multi-rank self test of pfem-partition. Run under MPI, e.g.
//! `mpirun -n 3 --oversubscribe target/debug/examples/partition_selftest`; exits non-zero when
//! any check fails on any rank. `tests/mpi_selftest.rs` runs it on 1, 2 and 3 ranks.

use std::collections::{BTreeMap, BTreeSet};
use std::process::ExitCode;

use pfem_partition::comm::{alltoallv_capped, gather_to_root_capped};
use pfem_partition::mpi::traits::*;
use pfem_partition::{
    agree_on_error, alltoallv, block_range, exscan_u64, fetch, gather_to_root, imbalance, migrate,
    partition_graph, try_migrate, Comm, Halo, PartitionError,
};

/// SplitMix64: deterministic and identical on every rank, so each rank can rebuild the global
/// picture for brute-force checks.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        mix(self.0)
    }
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Collects failures on this rank; all ranks must run the same checks in the same order.
struct Checks<'a> {
    comm: &'a Comm,
    passed: usize,
    failed: Vec<String>,
}

impl Checks<'_> {
    fn check(&mut self, name: &str, result: Result<(), String>) {
        match result {
            Ok(()) => self.passed += 1,
            Err(e) => self.failed.push(format!("{name}: {e}")),
        }
    }

    fn ensure(&mut self, name: &str, ok: bool, detail: impl FnOnce() -> String) {
        self.check(name, if ok { Ok(()) } else { Err(detail()) });
    }

    fn rank(&self) -> i32 {
        self.comm.rank()
    }

    fn size(&self) -> i32 {
        self.comm.size()
    }
}

fn check_alltoallv(c: &mut Checks) {
    let (me, size) = (c.rank(), c.size());
    // Rank 1 sends nothing at all, and some pairs are empty.
    let len = |from: i32, to: i32| {
        if from == 1 {
            0
        } else {
            ((from * 3 + to * 5) % 4) as usize
        }
    };
    let val = |from: i32, to: i32, j: usize| (from as u64) << 40 | (to as u64) << 20 | j as u64;
    let send: Vec<Vec<u64>> = (0..size)
        .map(|to| (0..len(me, to)).map(|j| val(me, to, j)).collect())
        .collect();
    for cap in [usize::MAX, 1, 3] {
        let got = if cap == usize::MAX {
            alltoallv(c.comm, &send)
        } else {
            alltoallv_capped(c.comm, &send, cap)
        };
        let ok = got.len() == size as usize
            && (0..size).all(|from| {
                let want: Vec<u64> = (0..len(from, me)).map(|j| val(from, me, j)).collect();
                got[from as usize] == want
            });
        c.ensure(&format!("alltoallv u64 cap {cap}"), ok, || {
            format!("{got:?}")
        });
    }
    // f64 payloads, including NaNs with payload bits, must arrive bit for bit.
    let bits = |from: i32, to: i32| mix((from * 31 + to) as u64) | 0x7FF0_0000_0000_0001;
    let send: Vec<Vec<f64>> = (0..size)
        .map(|to| vec![f64::from_bits(bits(me, to)), -0.0, 1.5])
        .collect();
    let got = alltoallv(c.comm, &send);
    let ok = (0..size).all(|from| {
        let g: Vec<u64> = got[from as usize].iter().map(|v| v.to_bits()).collect();
        g == vec![bits(from, me), (-0.0f64).to_bits(), 1.5f64.to_bits()]
    });
    c.ensure("alltoallv f64 bit-exact", ok, || format!("{got:?}"));
    // Short send list: missing destinations are empty.
    let got = alltoallv::<i32>(c.comm, &[]);
    c.ensure(
        "alltoallv all empty",
        got.len() == size as usize && got.iter().all(Vec::is_empty),
        || format!("{got:?}"),
    );
}

fn check_gather_exscan_imbalance(c: &mut Checks) {
    let (me, size) = (c.rank(), c.size());
    let local: Vec<u64> = (0..me as u64).map(|j| 100 * me as u64 + j).collect();
    let want: Vec<u64> = if me == 0 {
        (0..size as u64)
            .flat_map(|r| (0..r).map(move |j| 100 * r + j))
            .collect()
    } else {
        Vec::new()
    };
    let got = gather_to_root(c.comm, &local);
    c.ensure("gather_to_root", got == want, || format!("{got:?}"));
    let got = gather_to_root_capped(c.comm, &local, 1);
    c.ensure("gather_to_root cap 1", got == want, || format!("{got:?}"));

    let v = if me == 1 { 0 } else { 2 * me as u64 + 1 };
    let vals: Vec<u64> = (0..size)
        .map(|r| if r == 1 { 0 } else { 2 * r as u64 + 1 })
        .collect();
    let want = (
        vals[..me as usize].iter().sum::<u64>(),
        vals.iter().sum::<u64>(),
    );
    let got = exscan_u64(c.comm, v);
    c.ensure("exscan_u64", got == want, || format!("{got:?} != {want:?}"));

    let got = imbalance(c.comm, 0);
    c.ensure("imbalance all empty", got == 1.0, || format!("{got}"));
    let got = imbalance(c.comm, me as usize);
    let sum = (size * (size - 1) / 2) as f64;
    let want = if sum == 0.0 {
        1.0
    } else {
        (size - 1) as f64 / (sum / size as f64)
    };
    c.ensure("imbalance", (got - want).abs() < 1e-12, || {
        format!("{got} != {want}")
    });
}

fn check_errors_and_fetch(c: &mut Checks) {
    let (me, size) = (c.rank(), c.size());
    let got = agree_on_error(c.comm, None);
    c.ensure("agree_on_error none", got.is_none(), || format!("{got:?}"));
    let last = size - 1;
    let local = (me == last || me == 1).then(|| format!("boom from {me}"));
    let got = agree_on_error(c.comm, local);
    let want = format!("boom from {}", if size > 1 { 1 } else { 0 });
    c.ensure(
        "agree_on_error lowest rank",
        got.as_deref() == Some(&*want),
        || format!("{got:?}"),
    );

    // Each key is owned by key % size; owners answer key * 10 + their rank. Rank 1 asks nothing.
    let requests: Vec<(i32, u64)> = if me == 1 {
        Vec::new()
    } else {
        (0..20u64)
            .map(|j| mix(j + 7 * me as u64) % 1000)
            .map(|k| ((k % size as u64) as i32, k))
            .collect()
    };
    let got = fetch(c.comm, &requests, |&k| {
        Ok::<u64, PartitionError>(k * 10 + me as u64)
    });
    let want: Vec<u64> = requests.iter().map(|&(o, k)| k * 10 + o as u64).collect();
    c.ensure("fetch", got.as_ref() == Ok(&want), || format!("{got:?}"));

    let got = fetch(c.comm, &requests, |&k| {
        if k % size as u64 == last as u64 && k % 2 == 0 {
            Err(PartitionError::InvalidInput(format!("no answer for {k}")))
        } else {
            Ok(k as f64)
        }
    });
    let any_failing = (0..size)
        .filter(|&r| r != 1)
        .flat_map(|r| (0..20u64).map(move |j| mix(j + 7 * r as u64) % 1000))
        .any(|k| k % size as u64 == last as u64 && k % 2 == 0);
    let ok = match &got {
        Err(PartitionError::OnRank { rank, message }) => {
            any_failing && *rank == last && message.contains("no answer")
        }
        Ok(_) => !any_failing,
        Err(_) => false,
    };
    c.ensure("fetch answer error reaches everyone", ok, || {
        format!("{got:?}")
    });

    let bad: Vec<(i32, u64)> = if me == 0 { vec![(size, 1)] } else { Vec::new() };
    let got = fetch(c.comm, &bad, |&k| Ok::<u64, PartitionError>(k));
    c.ensure(
        "fetch bad owner fails everywhere",
        matches!(got, Err(PartitionError::OnRank { rank: 0, .. })),
        || format!("{got:?}"),
    );
}

/// A global point set that every rank regenerates identically.
struct Cloud {
    ids: Vec<u64>,
    pos: Vec<[f64; 2]>,
}

fn random_cloud(seed: u64, n: usize, lx: f64, ly: f64) -> Cloud {
    let mut rng = Rng(seed);
    let pos = (0..n).map(|_| [rng.unit() * lx, rng.unit() * ly]).collect();
    let ids = (0..n as u64).map(|i| mix(i ^ seed) >> 8).collect();
    Cloud { ids, pos }
}

fn lattice_cloud(nx: usize, ny: usize, h: f64) -> Cloud {
    let pos = (0..nx * ny)
        .map(|i| [(i % nx) as f64 * h, (i / nx) as f64 * h])
        .collect();
    let ids = (0..(nx * ny) as u64).map(|i| 3 * i + 11).collect();
    Cloud { ids, pos }
}

fn record_f64(id: u64, p: [f64; 2]) -> [f64; 3] {
    [f64::from_bits(mix(id)), p[0], p[1]]
}

fn check_halo(c: &mut Checks, name: &str, cloud: &Cloud, owner: &[i32], width: f64) {
    let me = c.rank();
    let mine: Vec<usize> = (0..cloud.ids.len()).filter(|&i| owner[i] == me).collect();
    let ids: Vec<u64> = mine.iter().map(|&i| cloud.ids[i]).collect();
    let pos: Vec<[f64; 2]> = mine.iter().map(|&i| cloud.pos[i]).collect();
    let halo = match Halo::build(c.comm, &ids, &pos, width) {
        Ok(h) => h,
        Err(e) => {
            c.check(&format!("halo {name} build"), Err(e.to_string()));
            return;
        }
    };

    // Brute force over the global cloud.
    let by_id: BTreeMap<u64, usize> = cloud.ids.iter().enumerate().map(|(i, &g)| (g, i)).collect();
    let d2 = |a: [f64; 2], b: [f64; 2]| {
        let dx = a[0] - b[0];
        let dy = a[1] - b[1];
        dx * dx + dy * dy
    };
    let near = |j: usize, w: f64| {
        mine.iter()
            .any(|&i| d2(cloud.pos[i], cloud.pos[j]) <= w * w)
    };
    let required: BTreeSet<u64> = (0..cloud.ids.len())
        .filter(|&j| owner[j] != me && near(j, width))
        .map(|j| cloud.ids[j])
        .collect();
    let ghosts: BTreeSet<u64> = halo.ghost_ids().iter().copied().collect();
    let missing: Vec<&u64> = required.difference(&ghosts).collect();
    c.ensure(&format!("halo {name} complete"), missing.is_empty(), || {
        format!(
            "rank {me} misses {} ghosts, e.g. {:?}",
            missing.len(),
            &missing[..missing.len().min(5)]
        )
    });
    let loose = width * (1.0 + 1e-6);
    let extra: Vec<u64> = halo
        .ghost_ids()
        .iter()
        .copied()
        .filter(|g| {
            by_id
                .get(g)
                .is_none_or(|&j| owner[j] == me || !near(j, loose))
        })
        .collect();
    c.ensure(&format!("halo {name} exact"), extra.is_empty(), || {
        format!("rank {me} has {} needless ghosts", extra.len())
    });
    let owners_ok = halo.ghost_ids().len() == halo.ghost_owners().len()
        && halo
            .ghost_ids()
            .iter()
            .zip(halo.ghost_owners())
            .all(|(g, &o)| by_id.get(g).is_some_and(|&j| owner[j] == o));
    let sorted = halo
        .ghost_owners()
        .iter()
        .zip(halo.ghost_ids())
        .collect::<Vec<_>>()
        .windows(2)
        .all(|w| w[0] < w[1]);
    c.ensure(
        &format!("halo {name} owners and order"),
        owners_ok && sorted,
        || format!("owners_ok {owners_ok} sorted {sorted}"),
    );

    // Exchanges: ghosts must get exactly their owners' records.
    let owned_f: Vec<f64> = mine
        .iter()
        .flat_map(|&i| record_f64(cloud.ids[i], cloud.pos[i]))
        .collect();
    let got = halo.exchange_f64(c.comm, &owned_f, 3);
    let want: Vec<u64> = halo
        .ghost_ids()
        .iter()
        .flat_map(|g| {
            let j = by_id.get(g).copied().unwrap_or(0);
            record_f64(*g, cloud.pos[j]).map(f64::to_bits)
        })
        .collect();
    let got_bits: Vec<u64> = got.iter().map(|v| v.to_bits()).collect();
    c.ensure(
        &format!("halo {name} exchange_f64 bit-exact"),
        got_bits == want,
        || format!("{} values vs {} expected", got_bits.len(), want.len()),
    );
    let owned_u: Vec<u64> = ids.iter().flat_map(|&g| [g, !g]).collect();
    let got = halo.exchange_u64(c.comm, &owned_u, 2);
    let want: Vec<u64> = halo.ghost_ids().iter().flat_map(|&g| [g, !g]).collect();
    c.ensure(&format!("halo {name} exchange_u64"), got == want, || {
        format!("{} values vs {} expected", got.len(), want.len())
    });
    let got = halo.exchange_f64(c.comm, &[], 0);
    c.ensure(&format!("halo {name} exchange k=0"), got.is_empty(), || {
        format!("{got:?}")
    });
    // A wrong length on one rank fails the checked exchange everywhere.
    let short = if me == c.size() - 1 {
        &owned_f[..owned_f.len().saturating_sub(1).min(owned_f.len())]
    } else {
        &owned_f[..]
    };
    let got = halo.try_exchange_f64(c.comm, short, 3);
    let last_has_items = owner.iter().any(|&o| o == c.size() - 1);
    let ok = if last_has_items {
        matches!(got, Err(PartitionError::OnRank { .. }))
    } else {
        got.is_ok()
    };
    c.ensure(
        &format!("halo {name} try_exchange length check"),
        ok,
        || format!("{:?}", got.err()),
    );
}

fn check_halos(c: &mut Checks) {
    let size = c.size();
    let cloud = random_cloud(42, 1500, 3.0, 1.0);
    // Strips along x: compact subdomains.
    let strips: Vec<i32> = cloud
        .pos
        .iter()
        .map(|p| ((p[0] / 3.0 * size as f64) as i32).min(size - 1))
        .collect();
    check_halo(c, "strips", &cloud, &strips, 0.07);
    // Scattered ownership, rank 1 owning nothing.
    let scattered: Vec<i32> = cloud
        .ids
        .iter()
        .map(|&g| {
            let r = (mix(g) % size as u64) as i32;
            if r == 1 {
                0
            } else {
                r
            }
        })
        .collect();
    check_halo(c, "scattered", &cloud, &scattered, 0.05);
    // Everything on rank 0.
    check_halo(c, "one owner", &cloud, &vec![0; cloud.ids.len()], 0.1);
    // Wide halo: every point is a ghost of every other rank.
    check_halo(c, "wide", &cloud, &strips, 5.0);
    // Lattice with the width equal to the spacing: neighbours sit exactly at the width.
    let lat = lattice_cloud(40, 17, 0.1);
    let diag: Vec<i32> = lat
        .pos
        .iter()
        .map(|p| (((p[0] + p[1]) * 7.0) as i32).rem_euclid(size))
        .collect();
    check_halo(c, "lattice", &lat, &diag, 0.1);
    // Far from the origin, so rounding of the cell computation matters.
    let far = Cloud {
        ids: lat.ids.clone(),
        pos: lat
            .pos
            .iter()
            .map(|p| [p[0] + 1.0e6, p[1] - 3.0e5])
            .collect(),
    };
    check_halo(c, "far lattice", &far, &diag, 0.1);
    // Empty everywhere.
    check_halo(
        c,
        "empty",
        &Cloud {
            ids: Vec::new(),
            pos: Vec::new(),
        },
        &[],
        0.1,
    );

    // Bad input on one rank fails on all.
    let me = c.rank();
    let width = if me == size - 1 { -1.0 } else { 0.1 };
    let got = Halo::build(c.comm, &[], &[], width);
    c.ensure(
        "halo bad width fails everywhere",
        matches!(&got, Err(PartitionError::OnRank { rank, .. }) if *rank == size - 1),
        || format!("{:?}", got.err()),
    );
}

fn check_migrate(c: &mut Checks) {
    let (me, size) = (c.rank(), c.size());
    // 300 items, initially block distributed over ranks other than 1 (rank 1 starts empty).
    let n = 300u64;
    let gid = |i: u64| mix(i) >> 4;
    let start_owner = |i: u64| {
        let r = (0..size)
            .find(|&r| block_range(n, r, size).contains(&i))
            .unwrap_or(0);
        if r == 1 {
            0
        } else {
            r
        }
    };
    let dest_of = |i: u64| (mix(i ^ 0xABC) % size as u64) as i32;
    let rec_f = |i: u64| [f64::from_bits(mix(i + 1)), i as f64, -(i as f64)];
    let rec_u = |i: u64| [mix(i + 2)];
    let mine: Vec<u64> = (0..n).filter(|&i| start_owner(i) == me).collect();
    let ids: Vec<u64> = mine.iter().map(|&i| gid(i)).collect();
    let dest: Vec<i32> = mine.iter().map(|&i| dest_of(i)).collect();
    let df: Vec<f64> = mine.iter().flat_map(|&i| rec_f(i)).collect();
    let du: Vec<u64> = mine.iter().flat_map(|&i| rec_u(i)).collect();

    let (ids2, f2, u2) = migrate(c.comm, &dest, &ids, &df, 3, &du, 1);
    let mut expect: Vec<u64> = (0..n).filter(|&i| dest_of(i) == me).collect();
    expect.sort_by_key(|&i| gid(i));
    let want_ids: Vec<u64> = expect.iter().map(|&i| gid(i)).collect();
    let want_f: Vec<u64> = expect
        .iter()
        .flat_map(|&i| rec_f(i).map(f64::to_bits))
        .collect();
    let want_u: Vec<u64> = expect.iter().flat_map(|&i| rec_u(i)).collect();
    let got_f: Vec<u64> = f2.iter().map(|v| v.to_bits()).collect();
    c.ensure(
        "migrate forward",
        ids2 == want_ids && got_f == want_f && u2 == want_u,
        || format!("{} ids vs {} expected", ids2.len(), want_ids.len()),
    );

    // Round trip back to the starting owners.
    let back: Vec<i32> = expect.iter().map(|&i| start_owner(i)).collect();
    let got = try_migrate(c.comm, &back, &ids2, &f2, 3, &u2, 1);
    let mut orig: Vec<u64> = mine.clone();
    orig.sort_by_key(|&i| gid(i));
    let ok = match &got {
        Ok((i3, f3, u3)) => {
            *i3 == orig.iter().map(|&i| gid(i)).collect::<Vec<_>>()
                && f3.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
                    == orig
                        .iter()
                        .flat_map(|&i| rec_f(i).map(f64::to_bits))
                        .collect::<Vec<_>>()
                && *u3 == orig.iter().flat_map(|&i| rec_u(i)).collect::<Vec<_>>()
        }
        Err(_) => false,
    };
    c.ensure("migrate round trip", ok, || format!("{:?}", got.err()));

    // Zero-stride records.
    let (i4, f4, u4) = migrate(c.comm, &dest, &ids, &[], 0, &[], 0);
    c.ensure(
        "migrate ids only",
        i4 == want_ids && f4.is_empty() && u4.is_empty(),
        || format!("{i4:?}"),
    );

    // Invalid destination: lenient version keeps the item, checked version fails everywhere.
    let (i5, _, _) = migrate(c.comm, &[-1], &[me as u64], &[], 0, &[], 0);
    c.ensure("migrate invalid dest stays", i5 == vec![me as u64], || {
        format!("{i5:?}")
    });
    let bad_dest = if me == 0 { size } else { me };
    let got = try_migrate(c.comm, &[bad_dest], &[me as u64], &[], 0, &[], 0);
    c.ensure(
        "try_migrate invalid dest fails everywhere",
        matches!(got, Err(PartitionError::OnRank { rank: 0, .. })),
        || format!("{got:?}"),
    );
}

/// Lattice graph with scrambled ids; vertex v = j * nx + i.
fn lattice_graph(nx: u64, ny: u64) -> (Vec<u64>, Vec<Vec<u64>>) {
    let id = |v: u64| mix(v + 99) >> 1;
    let mut ids = Vec::new();
    let mut nbrs = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            ids.push(id(j * nx + i));
            let mut nb = Vec::new();
            if i > 0 {
                nb.push(id(j * nx + i - 1));
            }
            if i + 1 < nx {
                nb.push(id(j * nx + i + 1));
            }
            if j > 0 {
                nb.push(id((j - 1) * nx + i));
            }
            if j + 1 < ny {
                nb.push(id((j + 1) * nx + i));
            }
            nbrs.push(nb);
        }
    }
    (ids, nbrs)
}

/// Outcome of partitioning from one starting distribution.
struct Partitioned {
    /// Local vertex ids.
    lids: Vec<u64>,
    /// New owner of each local vertex.
    parts: Vec<i32>,
    /// Flattened (gid, part) pairs of all vertices gathered on rank 0, sorted by gid.
    gathered: Vec<u64>,
}

/// Partitions the lattice starting from the distribution `start` (vertex -> rank).
fn partition_from(
    c: &mut Checks,
    ids: &[u64],
    nbrs: &[Vec<u64>],
    start: impl Fn(usize) -> i32,
) -> Result<Partitioned, PartitionError> {
    let me = c.rank();
    let local: Vec<usize> = (0..ids.len()).filter(|&v| start(v) == me).collect();
    let lids: Vec<u64> = local.iter().map(|&v| ids[v]).collect();
    let mut xadj = vec![0usize];
    let mut adj = Vec::new();
    for &v in &local {
        adj.extend_from_slice(&nbrs[v]);
        xadj.push(adj.len());
    }
    let parts = partition_graph(c.comm, &lids, &xadj, &adj)?;
    let pairs: Vec<u64> = lids
        .iter()
        .zip(&parts)
        .flat_map(|(&g, &p)| [g, p as u64])
        .collect();
    let all = gather_to_root(c.comm, &pairs);
    let mut sorted: Vec<(u64, u64)> = all.chunks_exact(2).map(|p| (p[0], p[1])).collect();
    sorted.sort_unstable();
    Ok(Partitioned {
        lids,
        parts,
        gathered: sorted.into_iter().flat_map(|(g, p)| [g, p]).collect(),
    })
}

fn check_partition(c: &mut Checks) {
    let (me, size) = (c.rank(), c.size());
    let (nx, ny) = (30u64, 20u64);
    let (ids, nbrs) = lattice_graph(nx, ny);
    let n = ids.len();
    let blocks = |v: usize| {
        (0..size)
            .find(|&r| block_range(n as u64, r, size).contains(&(v as u64)))
            .unwrap_or(0)
    };
    let a = partition_from(c, &ids, &nbrs, blocks);
    let b = partition_from(c, &ids, &nbrs, blocks);
    let z = partition_from(c, &ids, &nbrs, |_| 0);
    match (a, b, z) {
        (Ok(a), Ok(b), Ok(z)) => {
            let (lids, parts, ga) = (a.lids, a.parts, a.gathered);
            let (parts_b, gb, gz) = (b.parts, b.gathered, z.gathered);
            c.ensure(
                "partition_graph deterministic",
                parts == parts_b && ga == gb,
                || "two calls differ".into(),
            );
            c.ensure(
                "partition_graph independent of input distribution",
                ga == gz,
                || "block and single-rank inputs differ".into(),
            );
            c.ensure(
                "partition_graph parts in range",
                parts.iter().all(|&p| (0..size).contains(&p)),
                || format!("{parts:?}"),
            );
            // Move the vertices and measure the balance.
            let (owned, _, _) = migrate(c.comm, &parts, &lids, &[], 0, &[], 0);
            let imb = imbalance(c.comm, owned.len());
            c.ensure("partition_graph balance", imb <= 1.1, || {
                format!("imbalance {imb}")
            });
            // A good partition of a lattice cuts few edges: at most a few rows per part.
            if me == 0 {
                let part_of: BTreeMap<u64, u64> =
                    ga.chunks_exact(2).map(|p| (p[0], p[1])).collect();
                let cut = ids
                    .iter()
                    .zip(&nbrs)
                    .flat_map(|(g, nb)| nb.iter().map(move |h| (g, h)))
                    .filter(|(g, h)| part_of.get(g) != part_of.get(h))
                    .count()
                    / 2;
                let bound = (size as usize - 1) * 2 * (nx.max(ny) as usize);
                c.ensure("partition_graph edge cut", cut <= bound, || {
                    format!("cut {cut} > {bound}")
                });
            }
        }
        (a, b, z) => c.check(
            "partition_graph",
            Err(format!("{:?} {:?} {:?}", a.err(), b.err(), z.err())),
        ),
    }

    // A neighbour that is not a vertex fails on every rank.
    let got = if me == 0 {
        partition_graph(c.comm, &[1, 2], &[0, 1, 2], &[2, 77])
    } else {
        partition_graph(c.comm, &[], &[], &[])
    };
    let ok = if size == 1 {
        got.is_ok()
    } else {
        matches!(&got, Err(PartitionError::OnRank { rank: 0, message }) if message.contains("77"))
    };
    c.ensure("partition_graph unknown neighbour", ok, || {
        format!("{got:?}")
    });
    // Malformed CSR on the last rank fails everywhere.
    let got = if me == size - 1 {
        partition_graph(c.comm, &[5], &[0, 3], &[])
    } else {
        partition_graph(c.comm, &[], &[0], &[])
    };
    c.ensure(
        "partition_graph malformed csr",
        matches!(&got, Err(PartitionError::OnRank { rank, .. }) if *rank == size - 1),
        || format!("{got:?}"),
    );
}

fn run(comm: &Comm) -> (usize, Option<String>) {
    let mut c = Checks {
        comm,
        passed: 0,
        failed: Vec::new(),
    };
    check_alltoallv(&mut c);
    check_gather_exscan_imbalance(&mut c);
    check_errors_and_fetch(&mut c);
    check_halos(&mut c);
    check_migrate(&mut c);
    check_partition(&mut c);
    let local = (!c.failed.is_empty()).then(|| c.failed.join("\n"));
    (c.passed + c.failed.len(), agree_on_error(comm, local))
}

fn main() -> ExitCode {
    let Some(universe) = pfem_partition::mpi::initialize() else {
        eprintln!("partition_selftest: MPI is already initialised");
        return ExitCode::FAILURE;
    };
    let world = universe.world();
    let (me, size) = (world.rank(), world.size());
    let (total, failure) = run(&world);
    if me == 0 {
        match &failure {
            None => println!("partition_selftest on {size} ranks: {total} passed, 0 failed"),
            Some(msg) => println!(
                "partition_selftest on {size} ranks: FAILED (first failing rank's checks)\n{msg}"
            ),
        }
    }
    drop(world);
    drop(universe);
    if failure.is_some() {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}
