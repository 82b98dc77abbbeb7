//! `gaze-lidar`: the command-line front end. See `gaze-lidar --help`.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
