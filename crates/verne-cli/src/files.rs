//! A run's files: inputs opened through [`open_input_file`] and remembered, so that no output
//! replaces one; outputs written atomically (a temporary file beside the target, renamed into
//! place when the run succeeds, removed on an error or a signal); two outputs of one run that
//! are the same file refused before any work.

use std::fs::File;
use std::io::{self, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use crate::error::VerneError;
use crate::table::encode_field;
use csv::ByteRecord;

/// Where output goes: stdout, or a file written atomically. Records are CSV-encoded by
/// [`encode_field`]; a caller may also hand over text it encoded itself ([`Sink::write_encoded`]).
pub struct Sink {
    writer: Box<dyn Write + Send>,
    delimiter: u8,
    scratch: Vec<u8>,
    target: Option<(PathBuf, PathBuf)>,
    name: String,
}

impl Sink {
    /// `None` or `-` is stdout; a path is written through a temporary file in the same directory.
    pub fn create(path: Option<&Path>) -> Result<Sink, VerneError> {
        Sink::create_delimited(path, b',')
    }

    /// As [`Sink::create`], with another field delimiter (b' ' for halstreamer).
    pub fn create_delimited(path: Option<&Path>, delimiter: u8) -> Result<Sink, VerneError> {
        let (writer, target, name): (Box<dyn Write + Send>, _, String) = match path {
            Some(p) if p.as_os_str() != "-" => {
                let name = p.display().to_string();
                check_output_target(p).map_err(|e| VerneError::io(&name, e))?;
                let dest = output_destination(p);
                if dest.in_place {
                    let f = std::fs::OpenOptions::new()
                        .write(true)
                        .open(&dest.path)
                        .map_err(|e| VerneError::io(&name, e))?;
                    (Box::new(BufWriter::with_capacity(1 << 16, f)), None, name)
                } else {
                    remove_stale_temps(&dest.path);
                    let tmp = temp_path_for(&dest.path, "");
                    let f = File::create(&tmp).map_err(|e| {
                        VerneError::io(
                            &name,
                            io::Error::new(
                                e.kind(),
                                format!(
                                    "cannot create the temporary file {} beside it (the output is written there, then renamed): {e}",
                                    tmp.display()
                                ),
                            ),
                        )
                    })?;
                    (
                        Box::new(BufWriter::with_capacity(1 << 16, f)),
                        Some((tmp, dest.path)),
                        name,
                    )
                }
            }
            _ => (
                Box::new(BufWriter::with_capacity(1 << 16, io::stdout())),
                None,
                "<stdout>".to_string(),
            ),
        };
        if let Some((tmp, _)) = &target {
            crate::files::register_temp(tmp);
        }
        Ok(Sink {
            writer,
            delimiter,
            scratch: Vec::new(),
            target,
            name,
        })
    }

    /// A sink over any writer (tests, fuzzing, in-memory output).
    pub fn from_writer(w: Box<dyn Write + Send>, name: &str) -> Sink {
        Sink {
            writer: w,
            delimiter: b',',
            scratch: Vec::new(),
            target: None,
            name: name.to_string(),
        }
    }

    /// The same sink with `delimiter` between fields.
    pub fn with_delimiter(mut self, delimiter: u8) -> Sink {
        self.delimiter = delimiter;
        self
    }

    /// Passes everything written through `wrap` (a writer that turns the CSV into another
    /// format, such as [`crate::follow::write::GcodeProgram`]); call before the first write.
    pub fn wrap(&mut self, wrap: impl FnOnce(Box<dyn Write + Send>) -> Box<dyn Write + Send>) {
        let inner = std::mem::replace(&mut self.writer, Box::new(io::sink()));
        self.writer = wrap(inner);
    }

    /// The field delimiter of the records this sink writes.
    pub fn delimiter(&self) -> u8 {
        self.delimiter
    }

    /// Writes one record.
    pub fn write(&mut self, rec: &ByteRecord) -> Result<(), VerneError> {
        self.scratch.clear();
        if rec.len() == 1 && rec[0].is_empty() {
            // A lone empty field is written quoted, or the line would read as no record.
            self.scratch.extend_from_slice(b"\"\"");
        } else {
            for (i, f) in rec.iter().enumerate() {
                encode_field(&mut self.scratch, self.delimiter, i == 0, f);
            }
        }
        self.scratch.push(b'\n');
        let Sink {
            writer,
            scratch,
            name,
            ..
        } = self;
        writer
            .write_all(scratch)
            .map_err(|e| VerneError::io(name, e))
    }

    /// Writes records already encoded (with [`encode_field`] and this sink's delimiter, each
    /// ended by a line feed).
    pub fn write_encoded(&mut self, bytes: &[u8]) -> Result<(), VerneError> {
        self.writer
            .write_all(bytes)
            .map_err(|e| VerneError::io(&self.name, e))
    }

    /// Flushes and, for a file, renames the temporary file into place.
    pub fn finish(mut self) -> Result<(), VerneError> {
        let flushed = self
            .writer
            .flush()
            .map_err(|e| VerneError::io(&self.name, e));
        if let Err(e) = flushed {
            self.discard();
            return Err(e);
        }
        if let Some((tmp, dest)) = self.target.take() {
            // Close the file before renaming.
            drop(std::mem::replace(&mut self.writer, Box::new(io::sink())));
            let renamed = keep_attributes(&dest, &tmp).and_then(|_| std::fs::rename(&tmp, &dest));
            unregister_temp(&tmp);
            if let Err(e) = renamed {
                let _ = std::fs::remove_file(&tmp);
                return Err(VerneError::io(&self.name, e));
            }
        }
        Ok(())
    }

    /// Abandons the output: the temporary file is removed, the target is left untouched.
    pub fn discard(&mut self) {
        if let Some((tmp, _)) = self.target.take() {
            let _ = std::fs::remove_file(&tmp);
            unregister_temp(&tmp);
        }
    }
}

impl Drop for Sink {
    fn drop(&mut self) {
        self.discard();
    }
}

/// Where an output file is written ([`output_destination`]).
pub struct OutputDestination {
    /// The file to write or to rename into place (a symlink's target).
    pub path: PathBuf,
    /// Written directly, not through a temporary file renamed into place.
    pub in_place: bool,
}

/// Where output named `path` goes. A device, a FIFO or a socket (`/dev/null`, `/dev/stdout`, a
/// named pipe) is written in place: renaming a file over it would replace the node itself (and
/// `/dev/null` with it, for root). Anything else goes through a temporary file beside the
/// final file, renamed into place on success; a symlink is followed, so that it keeps pointing
/// at the output.
pub fn output_destination(path: &Path) -> OutputDestination {
    match std::fs::metadata(path) {
        Ok(m) if !m.is_file() && !m.is_dir() => OutputDestination {
            path: path.to_path_buf(),
            in_place: true,
        },
        Ok(_) if path.is_symlink() => OutputDestination {
            path: std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()),
            in_place: false,
        },
        // A symlink to a file not there yet: the file is created where the link points.
        Err(_) if path.is_symlink() => OutputDestination {
            path: match std::fs::read_link(path) {
                Ok(t) if t.is_relative() => path.parent().map_or(t.clone(), |d| d.join(&t)),
                Ok(t) => t,
                Err(_) => path.to_path_buf(),
            },
            in_place: false,
        },
        _ => OutputDestination {
            path: path.to_path_buf(),
            in_place: false,
        },
    }
}

/// Before a temporary file replaces `dest`: the mode and owner (owner only as root) of an
/// existing `dest` are given to the temporary file, so that the output keeps them. A hard link to `dest` keeps the
/// old content: the new file replaces the name, not the inode (docs/csv.md).
fn keep_attributes(dest: &Path, tmp: &Path) -> io::Result<()> {
    use std::os::unix::fs::MetadataExt;
    use std::os::unix::fs::PermissionsExt;
    let Ok(m) = std::fs::metadata(dest) else {
        return Ok(());
    };
    if !m.is_file() {
        return Ok(());
    }
    std::fs::set_permissions(tmp, std::fs::Permissions::from_mode(m.permissions().mode()))?;
    // Only root can give a file away; for anyone else the owner is already theirs.
    let _ = std::os::unix::fs::chown(tmp, Some(m.uid()), Some(m.gid()));
    Ok(())
}

/// The files this run reads (device and inode), so that no output replaces one of them.
static INPUT_FILES: std::sync::Mutex<Vec<(u64, u64)>> = std::sync::Mutex::new(Vec::new());

/// Opens an input file for reading and remembers it as an input of this run (see
/// `check_output_target`). Every command opens its input files through here.
pub fn open_input_file(path: &Path) -> io::Result<File> {
    let f = File::open(path)?;
    if let Ok(m) = f.metadata()
        && m.is_file()
        && let Ok(mut v) = INPUT_FILES.lock()
    {
        use std::os::unix::fs::MetadataExt;
        v.push((m.dev(), m.ino()));
    }
    Ok(f)
}

/// The largest machine file read (a complete one is a few kB).
pub const MAX_INPUT_FILE_BYTES: u64 = 16 << 20;

/// Reads a whole input file (a machine file), remembered as [`open_input_file`] does; a file
/// larger than [`MAX_INPUT_FILE_BYTES`] (or endless, `/dev/zero`) is an error, not a read until
/// memory runs out.
pub fn read_input_file(path: &Path) -> io::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    open_input_file(path)?
        .take(MAX_INPUT_FILE_BYTES + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_INPUT_FILE_BYTES {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "larger than {} MiB: expected a machine file (TOML or key,value CSV)",
                MAX_INPUT_FILE_BYTES >> 20
            ),
        ));
    }
    Ok(bytes)
}

/// Checks an output file before anything is computed or written: one of this run's input files
/// (the same file under any name: a hard or symbolic link too) is refused, since the run would
/// replace what it reads; so is an existing file without any write permission (root could
/// otherwise replace it).
/// `check_output_target`, and the directory the file goes to exists: checked before a
/// command computes anything, so a bad output path fails at once.
pub fn check_output_path(path: &Path) -> io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        return Err(io::Error::new(
            io::ErrorKind::NotFound,
            format!("the directory {} does not exist", dir.display()),
        ));
    }
    check_output_target(path)
}

fn check_output_target(path: &Path) -> io::Result<()> {
    use std::os::unix::fs::{MetadataExt, PermissionsExt};
    let Ok(m) = std::fs::metadata(path) else {
        return Ok(());
    };
    if m.is_file() && m.permissions().mode() & 0o222 == 0 {
        return Err(io::Error::new(
            io::ErrorKind::PermissionDenied,
            "the file is read-only: refusing to replace it (make it writable, or name another file)",
        ));
    }
    let same = INPUT_FILES
        .lock()
        .map(|v| v.contains(&(m.dev(), m.ino())))
        .unwrap_or(false);
    if same && m.is_file() {
        return Err(io::Error::other(
            "is an input of this run: refusing to overwrite it with the output (name another file)",
        ));
    }
    Ok(())
}

/// What an output is, to tell two of one run apart: standard output, an existing file (device
/// and inode: the same file under any name), or a file to be (its folder resolved).
#[derive(Debug, PartialEq)]
enum OutputIdentity {
    Stdout,
    Inode(u64, u64),
    Path(PathBuf),
}

fn output_identity(path: &Path) -> OutputIdentity {
    use std::os::unix::fs::MetadataExt;
    if path.as_os_str() == "-" || path == Path::new("/dev/stdout") {
        return OutputIdentity::Stdout;
    }
    if let Ok(m) = std::fs::metadata(path) {
        return OutputIdentity::Inode(m.dev(), m.ino());
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let dir = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
    OutputIdentity::Path(dir.join(path.file_name().unwrap_or_default()))
}

/// Refuses, before any work, two outputs of one run that are the same file (the same path once
/// resolved, or the same inode) or that both write standard output: one would replace or mix
/// with the other. `outputs` are (option, path) pairs.
pub fn check_distinct_outputs(outputs: &[(&str, &Path)]) -> Result<(), VerneError> {
    let ids: Vec<OutputIdentity> = outputs.iter().map(|(_, p)| output_identity(p)).collect();
    for i in 0..outputs.len() {
        for j in i + 1..outputs.len() {
            if ids[i] != ids[j] {
                continue;
            }
            let ((a, pa), (b, pb)) = (outputs[i], outputs[j]);
            return Err(VerneError::Usage(if ids[i] == OutputIdentity::Stdout {
                format!("{a} and {b} both write standard output: give one of them a file")
            } else {
                format!(
                    "{a} {} and {b} {} are the same file: each output of a run needs a file of its own",
                    pa.display(),
                    pb.display()
                )
            }));
        }
    }
    Ok(())
}

/// Writes `bytes` as the output file `path`, as [`Sink`] does: through a temporary file beside
/// it, renamed into place (nothing is left behind on an error), or in place for a device or a
/// FIFO ([`output_destination`]).
pub fn write_output(path: &Path, bytes: &[u8]) -> io::Result<()> {
    check_output_target(path)?;
    let dest = output_destination(path);
    if dest.in_place {
        return std::fs::write(&dest.path, bytes);
    }
    remove_stale_temps(&dest.path);
    let tmp = temp_path_for(&dest.path, "");
    std::fs::write(&tmp, bytes)
        .and_then(|_| keep_attributes(&dest.path, &tmp))
        .and_then(|_| std::fs::rename(&tmp, &dest.path))
        .inspect_err(|_| {
            let _ = std::fs::remove_file(&tmp);
        })
}

/// The longest file name the usual file systems take (bytes).
const NAME_MAX_BYTES: usize = 255;

/// The temporary file an output is written to before it is renamed into place:
/// `dir/.NAME.verne-PID.tmpEXT` beside the target (`ext`, e.g. `.png`, keeps the bitmap
/// encoder's format), or `dir/.verne-PID-HASH.tmpEXT` when that name would pass NAME_MAX. A run
/// killed by SIGKILL leaves it behind; the next run to the same target removes those of dead
/// processes ([`remove_stale_temps`]).
pub fn temp_path_for(p: &Path, ext: &str) -> PathBuf {
    let file = p
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let pid = std::process::id();
    let mut tmp = format!(".{file}.verne-{pid}.tmp{ext}");
    if tmp.len() > NAME_MAX_BYTES {
        tmp = format!(".verne-{pid}-{:016x}.tmp{ext}", name_hash(&file));
    }
    match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.join(tmp),
        _ => PathBuf::from(tmp),
    }
}

/// A stable hash of a file name (FNV-1a), for the shortened temporary name.
fn name_hash(name: &str) -> u64 {
    name.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Removes the temporary files of the target `p` left by runs that no longer exist (killed by
/// SIGKILL, which no handler sees): `.NAME.verne-PID.tmp*` (or the shortened form) whose PID is
/// not a running process. Another live run's file is left alone.
pub fn remove_stale_temps(p: &Path) {
    let file = p
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let dir = match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let long = format!(".{file}.verne-");
    let short = format!("-{:016x}.tmp", name_hash(&file));
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let pid = if let Some(rest) = name.strip_prefix(&long) {
            rest.split(".tmp")
                .next()
                .and_then(|p| p.parse::<u32>().ok())
        } else if let Some(rest) = name.strip_prefix(".verne-")
            && rest.contains(&short)
        {
            rest.split('-').next().and_then(|p| p.parse::<u32>().ok())
        } else {
            None
        };
        if let Some(pid) = pid
            && pid != std::process::id()
            && !Path::new(&format!("/proc/{pid}")).exists()
        {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

static TEMP_FILES: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

fn register_temp(p: &Path) {
    if let Ok(mut v) = TEMP_FILES.lock() {
        v.push(p.to_path_buf());
    }
}

fn unregister_temp(p: &Path) {
    if let Ok(mut v) = TEMP_FILES.lock() {
        v.retain(|q| q != p);
    }
}

/// Removes every temporary output file still open (for a signal handler or a fatal exit).
pub fn remove_temp_files() {
    if let Ok(v) = TEMP_FILES.lock() {
        for p in v.iter() {
            let _ = std::fs::remove_file(p);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_outputs_of_one_run_are_different_files() {
        let dir = std::env::temp_dir().join(format!("verne-outputs-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let a = dir.join("a.csv");
        std::fs::write(&a, "x").unwrap();
        let link = dir.join("b.csv");
        let _ = std::fs::remove_file(&link);
        std::fs::hard_link(&a, &link).unwrap();
        let dotted = dir.join(".").join("c.csv");
        let plain = dir.join("c.csv");
        let same = [
            (a.as_path(), a.as_path()),
            (a.as_path(), link.as_path()),
            (dotted.as_path(), plain.as_path()),
            (Path::new("-"), Path::new("/dev/stdout")),
        ];
        for (p, q) in same {
            assert!(
                check_distinct_outputs(&[("-o", p), ("--plot", q)]).is_err(),
                "{p:?} {q:?}"
            );
        }
        assert!(
            check_distinct_outputs(&[("-o", a.as_path()), ("--plot", plain.as_path())]).is_ok()
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
