//! `mmic`: encode and decode MMIC-I packets, print the spec tables. The logic lives in
//! [`mmic_host::cli`]; exit codes are documented there and in `mmic --help`.

use mmic_host::cli::{parse, run};
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = parse();
    match run(cli, &mut std::io::stdout().lock(), &mut std::io::stderr()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("mmic: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
