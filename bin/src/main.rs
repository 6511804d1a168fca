//! `mpm-cli`: the command-line face of psmpm (the commands live in the library,
//! `lib.rs`). Exit status: see `mpm_cli::error::EXIT_STATUS`.

fn main() -> std::process::ExitCode {
    mpm_cli::main()
}

/// The system allocator, counting heap bytes for `throughput`.
#[global_allocator]
static ALLOCATOR: mpm_cli::memory::Counting = mpm_cli::memory::Counting;
