//! Which files make up a bag: a bare .mcap file, or the files a bag directory's metadata.yaml
//! lists. The metadata is checked, not trusted: a listed file must be a regular file inside the
//! bag directory (no absolute paths, no `..`, no symbolic link leading out, no device), each is
//! read once, and a listing of which nothing exists falls back to the directory's .mcap files.
//! Everything the metadata got wrong is said in a note.

use super::BagError;
use std::path::{Component, Path, PathBuf};

/// The files of a bag and what was wrong with its metadata.
pub(super) struct BagFiles {
    pub files: Vec<PathBuf>,
    pub notes: Vec<String>,
}

/// Largest metadata.yaml read (bytes): 4 MiB (rosbag2 writes a few kB per topic and file).
const MAX_METADATA_BYTES: u64 = 4 << 20;

/// The files of the bag at `path`.
pub(super) fn bag_files(path: &Path) -> Result<BagFiles, BagError> {
    let io = |cause| BagError::Io {
        path: path.to_path_buf(),
        cause,
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_dir() {
        if !meta.is_file() {
            return Err(not_regular(path));
        }
        return Ok(BagFiles {
            files: check_compression(vec![path.to_path_buf()])?,
            notes: Vec::new(),
        });
    }
    let dir = path.canonicalize().map_err(io)?;
    let mut notes = Vec::new();
    let listed = listed_files(path, &dir, &mut notes);
    let in_dir = directory_mcaps(path, &dir).map_err(io)?;
    let files = if listed.is_empty() {
        in_dir
    } else {
        for f in in_dir.iter().filter(|f| !listed.contains(f)) {
            notes.push(format!(
                "{}: in the bag directory but not listed in metadata.yaml; not read",
                f.display()
            ));
        }
        listed
    };
    if files.is_empty() {
        return Err(BagError::NoMcap(path.to_path_buf()));
    }
    Ok(BagFiles {
        files: check_compression(files)?,
        notes,
    })
}

fn not_regular(path: &Path) -> BagError {
    BagError::Io {
        path: path.to_path_buf(),
        cause: std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file (a bag is a directory or an .mcap file)",
        ),
    }
}

/// The files metadata.yaml lists that may be read, once each, in its order; notes what is
/// wrong. Empty when there is no usable list.
fn listed_files(path: &Path, dir: &Path, notes: &mut Vec<String>) -> Vec<PathBuf> {
    let meta_path = path.join("metadata.yaml");
    let names = match read_metadata(&meta_path) {
        Ok(Some(names)) => names,
        Ok(None) => return Vec::new(),
        Err(why) => {
            notes.push(format!(
                "{}: {why}; the directory's .mcap files read instead",
                meta_path.display()
            ));
            return Vec::new();
        }
    };
    let mut files: Vec<PathBuf> = Vec::new();
    let mut any_missing = false;
    for name in &names {
        match listed_file(path, dir, name) {
            Ok(f) if files.contains(&f) => notes.push(format!(
                "metadata.yaml lists {name} more than once; read once"
            )),
            Ok(f) => files.push(f),
            Err(why) => {
                any_missing = true;
                notes.push(format!(
                    "metadata.yaml lists {name:?}, which {why}; not read"
                ));
            }
        }
    }
    if files.is_empty() && any_missing {
        notes.push(
            "no file metadata.yaml lists can be read: the directory's .mcap files read instead"
                .into(),
        );
    }
    files
}

/// `name` from metadata.yaml as a path to read: a regular file inside the bag directory.
fn listed_file(path: &Path, dir: &Path, name: &str) -> Result<PathBuf, &'static str> {
    let rel = Path::new(name);
    if name.is_empty() || !rel.components().all(|c| matches!(c, Component::Normal(_))) {
        return Err("is not a plain path inside the bag directory");
    }
    let joined = path.join(rel);
    let real = joined.canonicalize().map_err(|_| "does not exist")?;
    if !real.starts_with(dir) {
        return Err("leads outside the bag directory");
    }
    let meta = std::fs::metadata(&real).map_err(|_| "does not exist")?;
    if !meta.is_file() {
        return Err("is not a regular file");
    }
    Ok(joined)
}

/// `relative_file_paths` of metadata.yaml: `Ok(None)` if there is no metadata.yaml.
fn read_metadata(meta_path: &Path) -> Result<Option<Vec<String>>, String> {
    let meta = match std::fs::metadata(meta_path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(format!("cannot be read ({e})")),
    };
    if !meta.is_file() {
        return Err("is not a regular file".into());
    }
    if meta.len() > MAX_METADATA_BYTES {
        return Err(format!(
            "is {} bytes, more than a rosbag2 metadata file can be ({MAX_METADATA_BYTES})",
            meta.len()
        ));
    }
    let text = std::fs::read_to_string(meta_path).map_err(|e| format!("cannot be read ({e})"))?;
    super::check_yaml_shape(&text, MAX_METADATA_BYTES as usize)?;
    let doc: serde_yaml_ng::Value =
        serde_yaml_ng::from_str(&text).map_err(|e| format!("is not valid YAML ({e})"))?;
    let list = doc
        .get("rosbag2_bagfile_information")
        .and_then(|i| i.get("relative_file_paths"))
        .and_then(|l| l.as_sequence())
        .ok_or("has no rosbag2_bagfile_information.relative_file_paths list")?;
    Ok(Some(
        list.iter()
            .filter_map(|v| v.as_str().map(str::to_string))
            .collect(),
    ))
}

/// The regular .mcap files directly in the bag directory (symbolic links only if they stay
/// inside it), sorted by name.
fn directory_mcaps(path: &Path, dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut found: Vec<PathBuf> = std::fs::read_dir(path)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let name = p.to_string_lossy();
            (name.ends_with(".mcap") || name.ends_with(".mcap.zstd"))
                && p.canonicalize()
                    .is_ok_and(|r| r.starts_with(dir) && r.is_file())
        })
        .collect();
    // rosbag2's order: DIR_2.mcap before DIR_10.mcap (a split recording's files by number)
    found.sort_by_key(|p| split_number(p));
    Ok(found)
}

/// A file name as (stem before its number, number, name): `bag_10.mcap` → ("bag_", 10, …).
fn split_number(p: &Path) -> (String, u64, String) {
    let name = p
        .file_name()
        .map_or(String::new(), |n| n.to_string_lossy().into_owned());
    let stem = name.split('.').next().unwrap_or("");
    let digits = stem.len() - stem.trim_end_matches(|c: char| c.is_ascii_digit()).len();
    let (head, number) = stem.split_at(stem.len() - digits);
    (head.to_string(), number.parse().unwrap_or(0), name.clone())
}

fn check_compression(files: Vec<PathBuf>) -> Result<Vec<PathBuf>, BagError> {
    for f in &files {
        let name = f.to_string_lossy();
        if let Some(ext) = [".zstd", ".zst", ".lz4"]
            .iter()
            .find(|e| name.ends_with(*e))
        {
            return Err(BagError::Compressed {
                path: f.clone(),
                what: ext.trim_start_matches('.').into(),
            });
        }
    }
    Ok(files)
}

/// `file` opened for reading; it must be a regular file (not a device or a pipe).
pub(super) fn open_regular(file: &Path) -> Result<super::Source, BagError> {
    let io = |cause| BagError::Io {
        path: file.to_path_buf(),
        cause,
    };
    // checked before opening too: opening a FIFO would wait for a writer
    if !std::fs::metadata(file).map_err(io)?.is_file() {
        return Err(not_regular(file));
    }
    let f = std::fs::File::open(file).map_err(io)?;
    let meta = f.metadata().map_err(io)?;
    if !meta.is_file() {
        return Err(not_regular(file));
    }
    Ok(super::Source::File(std::sync::Arc::new(f), meta.len()))
}
