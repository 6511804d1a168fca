//! Any UTF-8 text as a command line (one argument per line, after `mpm-cli`):
//! `mpm_cli::check` parses it with the command line's clap definitions and
//! validates it as the command would before running (the scene, its overrides,
//! the limits), never panics, and refuses bad input as bad input (exit status 2).
//! A `run` that validates and is small is then run for at most two steps.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mpm_cli::{check, Checked};
use psmpm::simulation::{self, ParticlesRef};
use std::sync::atomic::{AtomicBool, Ordering};

/// The largest `run` the target steps through (particles; blocks of a block mesh).
const SMALL_PARTICLES: f64 = 2000.0;
const SMALL_BLOCKS: usize = 256;

fuzz_target!(|text: &str| {
    let args = std::iter::once("mpm-cli").chain(text.split('\n'));
    match check(args) {
        Ok(Checked::Run(scene)) => {
            scene.validate().expect("check returns validated scenes");
            let small = scene.estimated_particle_count() <= SMALL_PARTICLES
                && scene.blocks().is_none_or(|[x, y]| x * y <= SMALL_BLOCKS);
            if !small {
                return;
            }
            let stop = AtomicBool::new(false);
            let mut observer = |r: &psmpm::driver::StepReport, _: ParticlesRef<'_>| {
                if r.step >= 2 {
                    stop.store(true, Ordering::Relaxed);
                }
            };
            // A set-up error is a typed error (it is what `run` reports as bad input).
            let summary = if scene.dim == 2 {
                simulation::observe_2d_until(&scene, &mut observer, &stop).map(|o| o.summary)
            } else {
                simulation::observe_1d_until(&scene, &mut observer, &stop).map(|o| o.summary)
            };
            if let Ok(summary) = summary {
                assert!(summary.steps <= 2, "{} steps", summary.steps);
            }
        }
        Ok(Checked::Scenes(scenes)) => {
            for s in &scenes {
                s.validate().expect("check returns validated scenes");
            }
        }
        Ok(Checked::Parsed) => {}
        Err(e) => {
            assert_eq!(e.exit_code(), 2, "{e}");
            assert!(!e.to_string().is_empty());
        }
    }
});
