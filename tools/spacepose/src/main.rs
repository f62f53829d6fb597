//! `spacepose`: the command line of the spacepose suite.
//!
//! Errors are printed as one line (`error: …` with the chain of causes) and
//! exit with status 2; nothing panics on bad input.

use clap::Parser;
use spacepose::cli::{Cli, Command, EvalCommand};
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = Cli::parse();
    init_logging(cli.verbose);
    let result = match cli.command {
        Command::Sim(args) => spacepose_eval::sim::run(&args),
        Command::Dataset(args) => spacepose_eval::dataset::run(&args),
        Command::Train(args) => spacepose_eval::train::run(&args),
        Command::Track(args) => spacepose_eval::track::run(&args),
        Command::Eval(EvalCommand::Tracking(args)) => spacepose_eval::tracking::run(&args),
        Command::Eval(EvalCommand::Cnn(args)) => spacepose_eval::cnn::run(&args),
        Command::Eval(EvalCommand::Tm(args)) => spacepose_eval::tm::run(&args),
        Command::Eval(EvalCommand::Tables(args)) => spacepose_eval::tables::run(&args),
        Command::Target(command) => spacepose_eval::target::run(&command),
        Command::Calibrate(command) => spacepose_eval::calibrate::run(&command),
        Command::Up(args) => spacepose::suite::cmd::up(&args),
        Command::Supervise(args) => spacepose::suite::cmd::supervise(&args),
        Command::Swap(args) => spacepose::suite::cmd::swap(&args),
        Command::Status(args) => spacepose::suite::cmd::status(&args),
        Command::Down(args) => spacepose::suite::cmd::down(&args),
        Command::Demo(args) => spacepose::suite::cmd::demo(&args),
        Command::Replay(args) => spacepose::suite::cmd::replay(&args),
        Command::Ground(args) => spacepose::suite::cmd::ground(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

fn init_logging(verbose: bool) {
    let default = if verbose { "info" } else { "warn" };
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(default));
    tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .init();
}
