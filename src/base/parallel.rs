//! Work spread over scoped threads, results in the order of the items: one thread per
//! item ([`each`]: a few large independent jobs, such as a kit's drums) or one run of
//! consecutive items per core ([`chunked`]: many small ones, such as a database's takes).
//! A job's panic is raised again in the caller, as if the work had run there.

use std::thread::ScopedJoinHandle;

/// `f` of each item, each on a thread of its own; in order.
pub fn each<T: Send, R: Send>(
    items: impl IntoIterator<Item = T>,
    f: impl Fn(T) -> R + Sync,
) -> Vec<R> {
    std::thread::scope(|scope| {
        let f = &f;
        let jobs: Vec<_> = items
            .into_iter()
            .map(|item| scope.spawn(move || f(item)))
            .collect();
        joined(jobs)
    })
}

/// The cores this process may run on (its CPU affinity: 1 under `taskset -c 0`).
pub fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// `f` of each item, the items split into one run of consecutive ones per available
/// core, each run on a thread of its own; in order.
pub fn chunked<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let cores = cores();
    let run = items.len().div_ceil(cores).max(1);
    std::thread::scope(|scope| {
        let f = &f;
        let jobs: Vec<_> = items
            .chunks(run)
            .map(|part| scope.spawn(move || part.iter().map(f).collect::<Vec<R>>()))
            .collect();
        joined(jobs).into_iter().flatten().collect()
    })
}

/// The jobs' results in order; a job's panic raised again here.
fn joined<R>(jobs: Vec<ScopedJoinHandle<'_, R>>) -> Vec<R> {
    jobs.into_iter()
        .map(|job| {
            job.join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both keep the items' order whatever the threads' timing: later items finish first.
    #[test]
    fn results_come_in_the_items_order() {
        let slow_first = |i: &u64| {
            std::thread::sleep(std::time::Duration::from_millis(20u64.saturating_sub(*i)));
            i * i
        };
        let items: Vec<u64> = (0..20).collect();
        let squares: Vec<u64> = items.iter().map(|i| i * i).collect();
        assert_eq!(chunked(&items, slow_first), squares);
        assert_eq!(each(&items, slow_first), squares);
        assert!(chunked(&[] as &[u64], slow_first).is_empty());
        assert!(each(Vec::<u64>::new(), |i| i).is_empty());
    }

    /// A job's panic reaches the caller with its own message.
    #[test]
    fn a_panic_in_a_job_reaches_the_caller() {
        let caught = std::panic::catch_unwind(|| {
            each([1, 2, 3], |i| {
                assert!(i != 2, "item two fails");
                i
            })
        });
        let message = caught.unwrap_err();
        let text = message
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| message.downcast_ref::<&str>().map(|s| s.to_string()));
        assert_eq!(text.as_deref(), Some("item two fails"));
    }
}
