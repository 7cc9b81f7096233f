//! The timing thread held on one CPU, the one that was idlest when timing began: a thread that
//! moves between cores mid-measurement measures two of them, and one held on a core another
//! process keeps busy measures its share of that core, which varies from pass to pass (on
//! this project's 2-core machine, with a loop busy on one core, held on the CPU it happened to
//! run on, 2 of 10 CPU designs changed their answer; held on the idle one, see
//! docs/performance.md).

/// Holds the calling thread on one CPU until dropped, then allows its former CPUs again
/// (Linux; elsewhere nothing).
pub(crate) struct Pinned {
    #[cfg(target_os = "linux")]
    former: Option<nix::sched::CpuSet>,
}

/// How long the CPUs' idle time is watched before choosing one.
#[cfg(target_os = "linux")]
const WATCH: std::time::Duration = std::time::Duration::from_millis(50);

impl Pinned {
    /// Held on the CPU, of those this thread may run on, that was idle longest over [`WATCH`]
    /// (the one it runs on where `/proc/stat` cannot be read or every CPU was as busy).
    pub(crate) fn to_idlest_cpu() -> Self {
        #[cfg(target_os = "linux")]
        {
            use nix::sched::{sched_getaffinity, sched_getcpu, sched_setaffinity, CpuSet};
            use nix::unistd::Pid;
            let former = sched_getaffinity(Pid::from_raw(0)).ok();
            let allowed = |cpu: usize| {
                former
                    .as_ref()
                    .is_none_or(|set| set.is_set(cpu).unwrap_or(false))
            };
            let before = idle_times();
            std::thread::sleep(WATCH);
            let idlest = idlest(&before, &idle_times(), allowed);
            let pinned = idlest.or_else(|| sched_getcpu().ok()).and_then(|cpu| {
                let mut one = CpuSet::new();
                one.set(cpu).ok()?;
                sched_setaffinity(Pid::from_raw(0), &one).ok()
            });
            Self {
                former: former.filter(|_| pinned.is_some()),
            }
        }
        #[cfg(not(target_os = "linux"))]
        Self {}
    }
}

/// Each CPU's idle and waiting time so far (`/proc/stat`'s `cpuN` lines, fourth and fifth
/// fields, in clock ticks); none where the file cannot be read.
#[cfg(target_os = "linux")]
fn idle_times() -> Vec<(usize, u64)> {
    parse_idle_times(&std::fs::read_to_string("/proc/stat").unwrap_or_default())
}

/// Of the CPUs in both readings that `allowed` admits, the one idle longest between them (the
/// lowest numbered of equals); none where no CPU was idle at all.
#[cfg(target_os = "linux")]
fn idlest(
    before: &[(usize, u64)],
    after: &[(usize, u64)],
    allowed: impl Fn(usize) -> bool,
) -> Option<usize> {
    after
        .iter()
        .filter(|&&(cpu, _)| allowed(cpu))
        .filter_map(|&(cpu, idle)| {
            let earlier = before.iter().find(|(c, _)| *c == cpu)?.1;
            Some((cpu, idle.saturating_sub(earlier)))
        })
        .filter(|&(_, idle)| idle > 0)
        .max_by_key(|&(cpu, idle)| (idle, core::cmp::Reverse(cpu)))
        .map(|(cpu, _)| cpu)
}

#[cfg(target_os = "linux")]
fn parse_idle_times(stat: &str) -> Vec<(usize, u64)> {
    stat.lines()
        .filter_map(|line| {
            let mut fields = line.split_ascii_whitespace();
            let cpu: usize = fields.next()?.strip_prefix("cpu")?.parse().ok()?;
            let ticks: Vec<u64> = fields
                .take(5)
                .map(|f| f.parse().ok())
                .collect::<Option<_>>()?;
            Some((cpu, ticks.get(3)? + ticks.get(4)?))
        })
        .collect()
}

impl Drop for Pinned {
    fn drop(&mut self) {
        #[cfg(target_os = "linux")]
        if let Some(former) = &self.former {
            // Nothing to do if it fails: the thread stays where it is, still correct.
            let _ = nix::sched::sched_setaffinity(nix::unistd::Pid::from_raw(0), former);
        }
    }
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;
    use nix::sched::{sched_getaffinity, CpuSet};
    use nix::unistd::Pid;

    /// Timing pins the thread to one CPU and gives it back its CPUs afterwards.
    #[test]
    fn pinning_restores_the_affinity() {
        let count = |set: &CpuSet| {
            (0..CpuSet::count())
                .filter(|&cpu| set.is_set(cpu).unwrap_or(false))
                .count()
        };
        let before = sched_getaffinity(Pid::from_raw(0)).unwrap();
        {
            let _pinned = Pinned::to_idlest_cpu();
            assert_eq!(count(&sched_getaffinity(Pid::from_raw(0)).unwrap()), 1);
        }
        assert_eq!(sched_getaffinity(Pid::from_raw(0)).unwrap(), before);
    }

    /// The per-CPU lines are read, the total line and others skipped; idle is the fourth and
    /// fifth numbers (idle and I/O wait).
    #[test]
    fn idle_times_come_from_the_per_cpu_lines() {
        let stat = "cpu  10 0 20 300 4 0 0 0 0 0\n\
                    cpu0 1 2 3 40 5 6 7 8 0 0\n\
                    cpu1 9 9 9 100 1 0 0 0 0 0\n\
                    intr 12345\n";
        assert_eq!(parse_idle_times(stat), vec![(0, 45), (1, 101)]);
    }

    /// The idlest allowed CPU is chosen: the busiest and the disallowed never, equals go to
    /// the lowest, and none where nothing was idle (the caller then stays where it runs).
    #[test]
    fn the_idlest_allowed_cpu_is_chosen() {
        let before = [(0, 100), (1, 100), (2, 100), (3, 100)];
        let after = [(0, 100), (1, 104), (2, 109), (3, 109)];
        assert_eq!(idlest(&before, &after, |_| true), Some(2));
        assert_eq!(idlest(&before, &after, |cpu| cpu != 2), Some(3));
        assert_eq!(idlest(&before, &after, |cpu| cpu < 2), Some(1));
        assert_eq!(idlest(&before, &after, |cpu| cpu == 0), None);
        assert_eq!(idlest(&before, &[(5, 900)], |_| true), None);
    }
}
