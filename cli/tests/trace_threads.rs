//! The problem's threads in the trace: where m = 2p ≥ `fricont::PARALLEL_MIN_ORDER`, each
//! call into a path runs its dense passes (LU factorisations, triangular solves, products
//! with W) on a private pool of the problem's threads, started for the call and stopped
//! after it, while the path's logic and its callbacks stay on the calling thread.

use std::sync::Arc;

use fricont::path::{Path, PathOptions};
use fricont_exchange::generator::{RectSpec, generate};

/// This process's threads that fricont's pools start (named `fricont-0`, …), from the
/// kernel's own list of the process's threads: their number, and the CPU time they have
/// used (user + system, in clock ticks).
fn pool_threads_and_ticks() -> (usize, u64) {
    let Ok(dir) = std::fs::read_dir("/proc/self/task") else {
        return (0, 0);
    };
    let mut out = (0, 0);
    for task in dir.filter_map(|e| e.ok()) {
        let comm = std::fs::read_to_string(task.path().join("comm")).unwrap_or_default();
        if !comm.trim_end().starts_with("fricont-") {
            continue;
        }
        out.0 += 1;
        // Fields 14 and 15 of stat (utime, stime), counted after the ")" that ends the name.
        let stat = std::fs::read_to_string(task.path().join("stat")).unwrap_or_default();
        let rest = stat.rsplit_once(')').map(|(_, r)| r).unwrap_or("");
        let f: Vec<&str> = rest.split_whitespace().collect();
        let tick = |k: usize| f.get(k).and_then(|v| v.parse::<u64>().ok()).unwrap_or(0);
        out.1 += tick(11) + tick(12);
    }
    out
}

fn pool_threads() -> usize {
    pool_threads_and_ticks().0
}

/// Waits (up to 5 s) for the threads of a stopped pool to end: rayon tells them to stop
/// when the pool is dropped and they exit on their own.
fn pool_threads_after_stop() -> usize {
    for _ in 0..500 {
        if pool_threads() == 0 {
            return 0;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    pool_threads()
}

/// A 1025 × 5-node rectangle (p = 1024, m = 2048) traced for 40 transitions on one thread
/// and on two: the same events (α to 1e-12 relative, nodes, classes, folds) and the same
/// solution at a traced α; with two, the monitor (on the calling thread, inside `run`)
/// sees the call's pool of two threads, busy (they have used CPU time by the last
/// transition), and none is left once `run` returns. With one, no thread is started.
#[cfg(target_os = "linux")]
#[test]
fn trace_on_two_threads_gives_the_events_of_one() {
    let spec = RectSpec {
        nx: 1025,
        ny: 5,
        lx: 8.0,
        ly: 1.0,
        ..RectSpec::press_shear()
    };
    let case = generate(&spec).expect("generate");
    assert!(2 * case.p() >= fricont::PARALLEL_MIN_ORDER);
    let caller = std::thread::current().id();
    let run = |threads: usize| {
        let problem = Arc::new(case.builder().threads(threads).build().expect("problem"));
        assert_eq!(problem.threads(), threads);
        assert_eq!(pool_threads_after_stop(), 0, "the set-up's pool is stopped");
        let mut opts = PathOptions::window(case.alpha_start, case.alpha_end);
        opts.max_steps = 40;
        let mut path = Path::new(problem, case.load().expect("load"), opts).expect("path");
        path.start(case.alpha_start, None).expect("start");
        let mut seen = Vec::new();
        path.run_monitored(|_, _| {
            assert_eq!(std::thread::current().id(), caller);
            seen.push(pool_threads_and_ticks());
            std::ops::ControlFlow::Continue(())
        })
        .expect("run");
        assert_eq!(pool_threads_after_stop(), 0, "{threads} threads: pool left");
        (path, seen)
    };
    let (one, seen1) = run(1);
    let (two, seen2) = run(2);
    assert!(
        seen1.iter().all(|k| k.0 == 0),
        "one thread started {seen1:?}"
    );
    assert!(seen2.iter().all(|k| k.0 == 2), "{seen2:?}");
    assert!(
        seen2.last().is_some_and(|k| k.1 > 0),
        "an idle pool: {seen2:?}"
    );
    let (e1, e2) = (one.events(), two.events());
    assert_eq!(e1.len(), 40);
    assert_eq!(e1.len(), e2.len());
    for (x, y) in e1.iter().zip(e2) {
        assert!(
            (x.alpha - y.alpha).abs() <= 1e-12 * x.alpha.abs().max(1.0),
            "event {}: α {:e} vs {:e}",
            x.index + 1,
            x.alpha,
            y.alpha
        );
        assert_eq!(
            (x.node, x.from, x.to, x.fold, x.bifurcation),
            (y.node, y.from, y.to, y.fold, y.bifurcation)
        );
    }
    // A solution inside the traced range, on a pool again for two.
    let alpha = 0.5 * (e1[10].alpha + e1[11].alpha);
    let (mut one, mut two) = (one, two);
    let (s1, s2) = (
        one.solutions_at(alpha).expect("one"),
        two.solutions_at(alpha).expect("two"),
    );
    assert_eq!(s1.len(), 1);
    assert_eq!(s2.len(), 1);
    let (l1, l2) = (&s1[0].state.lambda_n, &s2[0].state.lambda_n);
    let scale = l1.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (a, b) in l1.iter().zip(l2) {
        assert!((a - b).abs() <= 1e-10 * scale, "λν {a:e} vs {b:e}");
    }
}
