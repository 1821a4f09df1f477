//! TEMPORARY: per-phase memory probe (issue 10 memory breakdown). With PFEM_MEM_PROBE set,
//! prints VmRSS now and VmHWM since the last probe, then resets VmHWM.

pub fn probe(label: &str) {
    if std::env::var_os("PFEM_MEM_PROBE").is_none() {
        return;
    }
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let field = |name: &str| -> u64 {
        status
            .lines()
            .find_map(|l| l.strip_prefix(name))
            .and_then(|v| v.split_whitespace().next())
            .and_then(|v| v.parse().ok())
            .unwrap_or(0)
    };
    let rank = std::env::var("OMPI_COMM_WORLD_RANK").unwrap_or_default();
    eprintln!(
        "[mem r{rank}] {label:<40} rss {:>8.1} MB  peak-since-last {:>8.1} MB",
        field("VmRSS:") as f64 / 1024.0,
        field("VmHWM:") as f64 / 1024.0
    );
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}
