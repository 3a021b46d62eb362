//! The `sweephold` binary run as a user runs it: one integration-test binary whose modules
//! are the verbs' and the promises' tests. One binary, not one per file: each test binary
//! links the whole CLI library, and linking them one by one took most of the tests' build.
//!
//! The tests run as threads of this one process, in parallel: a test changes nothing of
//! the process (no `std::env::set_var`, no current folder, no signal handler); what a run
//! needs is given to its child `Command`, and each test works in its own folder
//! (`support::scratch`).
//!
//! Run one module's tests with `cargo test -p sweephold --test cli MODULE::`.

mod support;

mod aircraft_file;
#[cfg(unix)]
mod bad_inputs_battery;
mod board_logs;
mod board_sim;
mod board_sim_airborne;
mod board_sim_faults_at_start;
mod board_sim_flash;
mod campaign;
mod decode;
mod degenerate_fits;
mod exit_status;
mod flight_logs;
#[cfg(unix)]
mod fly_signals;
mod frf_csv;
mod frf_dump_origin;
mod frf_inputs;
mod gust_pulse;
mod identify;
mod inputs;
#[cfg(unix)]
mod links;
mod margins;
#[cfg(unix)]
mod one_run_per_folder;
mod power_up_log;
#[cfg(target_os = "linux")]
mod qemu_signals;
#[cfg(unix)]
mod signals;
mod stderr_full;
#[cfg(target_os = "linux")]
mod stdout;
mod steady_flights;
mod structures_ticks;
mod test_list;
mod trim_points;
mod tune;
