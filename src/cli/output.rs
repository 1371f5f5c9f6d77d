//! What commands write: standard output that tolerates a closed pipe, one run's result as JSON,
//! and JSON and CSV files written whole or not at all.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::{anyhow, Context};

/// Where one run's result goes besides its table: JSON on stdout instead, and a JSON file.
#[derive(clap::Args)]
pub struct ResultArgs {
    /// Print the result as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Also write the JSON result, with every impact or slice in detail, to this file.
    #[arg(long, short)]
    pub out: Option<PathBuf>,
}

impl ResultArgs {
    /// Writes `result` to the `--out` file, when one is given.
    pub fn write(&self, result: &impl serde::Serialize) -> anyhow::Result<()> {
        match &self.out {
            Some(path) => write_json(path, result),
            None => Ok(()),
        }
    }
}

/// `println!` that ignores a closed stdout (`grit status --json | head`) instead of panicking.
macro_rules! say {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($t)*);
    }};
}
pub(crate) use say;

/// Writes `path` through a temporary file in the same folder and a rename, so a reader, or a
/// run killed midway, never sees half a file.
fn write_atomic(
    path: &Path,
    fill: impl FnOnce(&mut BufWriter<File>) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let name = path
        .file_name()
        .ok_or_else(|| anyhow!("{}: not a file name", path.display()))?;
    let tmp = path.with_file_name(format!(
        ".{}.{}.tmp",
        name.to_string_lossy(),
        std::process::id()
    ));
    let written = (|| -> anyhow::Result<()> {
        let mut w = BufWriter::new(File::create(&tmp)?);
        fill(&mut w)?;
        w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        std::fs::rename(&tmp, path)?;
        Ok(())
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written.with_context(|| format!("writing {}", path.display()))
}

/// Fails now, naming `flag`, if `path` could not be written later: its folder must take the
/// temporary file `write_atomic` writes there, so a long run does not end in a write error.
pub fn check_writable(flag: &str, path: &Path) -> anyhow::Result<()> {
    if path.is_dir() {
        anyhow::bail!("{flag} {}: is a folder; give a file name", path.display());
    }
    write_atomic(&probe_path(path)?, |_| Ok(()))
        .and_then(|()| Ok(std::fs::remove_file(probe_path(path)?)?))
        .with_context(|| format!("{flag} {}: cannot write there", path.display()))
}

/// A file beside `path` that nothing else uses, for `check_writable`.
fn probe_path(path: &Path) -> anyhow::Result<std::path::PathBuf> {
    let name = path
        .file_name()
        .ok_or_else(|| anyhow!("{}: not a file name", path.display()))?;
    Ok(path.with_file_name(format!(".{}.probe", name.to_string_lossy())))
}

/// Writes `bytes` to `path`, atomically.
pub fn write_bytes(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    write_atomic(path, |w| Ok(w.write_all(bytes)?))
}

/// Writes `value` as pretty JSON with a final newline, atomically.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> anyhow::Result<()> {
    write_atomic(path, |w| {
        serde_json::to_writer_pretty(&mut *w, value)?;
        w.write_all(b"\n")?;
        Ok(())
    })
}

/// Writes `rows` as CSV (one header row of the serde field names), atomically.
pub fn write_csv<T: serde::Serialize>(path: &Path, rows: &[T]) -> anyhow::Result<()> {
    write_atomic(path, |w| {
        let mut c = csv::Writer::from_writer(w);
        for r in rows {
            c.serialize(r)?;
        }
        c.flush()?;
        Ok(())
    })
}
