//! Film tables on disk: built once per bearing type and lubricant, shared by every twin on the
//! machine.
//!
//! A table is a pure function of its inputs: the bearing geometry, the lubricant as the table
//! holds it (density and the viscosity it was built with; a run-time viscosity scale is applied
//! to the tabulated film, not to the key), the film grid, the table's own resolution and domain
//! (nodes in ε and ψ, the largest ε, the grid phases averaged) and the solver that makes it. The
//! key spells all of these out, with [`SOLVER_VERSION`] and a fingerprint of the source of the
//! solver and of the table builder, so a table made by other code is never read.
//!
//! File: `film-table-<md5 of the key>.bin` in the cache directory, little-endian:
//! magic `RTFILMTB`, format version (u32), key length (u32) and key (UTF-8), n_θ (u32), u_max
//! (f64), payload length (u64), CRC-32 of the payload (u32), payload (the nodes' 14 values, then
//! the mid-plane profiles, f64). Written to a temporary file in the same directory and renamed
//! over the target (atomic on POSIX), so a reader sees the whole old file or the whole new one.
//! A file that does not verify (magic, version, key, sizes, checksum, finite values) is reported
//! and rebuilt, never used. A lock file serialises builders of the same table (the others wait
//! and load the result), bounded in time: a cold fleet builds each table once.

use super::TABLE_SOURCES;
use super::{FilmTable, Node, SliceFlow, TableResolution, MAX_ECCENTRICITY_RATIO, ROW_ECC_CAP};
use crate::film::{BearingGeometry, FilmError, FilmGrid, Lubricant};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::RwLock;
use std::time::{Duration, Instant};

/// Version of the file layout; bump when it changes.
pub const FORMAT_VERSION: u32 = 1;
/// Version of the numbers in a table (the finite solver and the table's node definition); bump
/// when either changes in a way the source fingerprint would not show.
pub const SOLVER_VERSION: u32 = 2;

const MAGIC: &[u8; 8] = b"RTFILMTB";
/// Values per node in the file (the fields of `Node`, in order).
const NODE_VALUES: usize = 14;
/// Longest wait for another process building the same table before building it here too.
const LOCK_WAIT: Duration = Duration::from_secs(600);

/// Something wrong with the cache that did not stop the table: said once, then carried on.
#[derive(Debug, Clone, PartialEq)]
pub struct CacheWarning {
    /// The file or directory concerned.
    pub path: PathBuf,
    /// What was wrong and what was done instead.
    pub what: String,
}

impl std::fmt::Display for CacheWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "film table cache {}: {}", self.path.display(), self.what)
    }
}

/// Where a table came from.
#[derive(Debug, Clone, PartialEq)]
pub enum TableOrigin {
    /// Already in this process.
    InProcess,
    /// Read from this cache file.
    Loaded(PathBuf),
    /// Built here; stored in this file, or not cached.
    Built(Option<PathBuf>),
}

impl std::fmt::Display for TableOrigin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TableOrigin::InProcess => f.write_str("shared"),
            TableOrigin::Loaded(p) => write!(f, "loaded from {}", p.display()),
            TableOrigin::Built(Some(p)) => write!(f, "built, stored in {}", p.display()),
            TableOrigin::Built(None) => f.write_str("built, not cached"),
        }
    }
}

/// The result of looking a table up on disk.
// one a table load, never stored or in a hot path: the table unboxed (its nodes are on the heap)
#[allow(clippy::large_enum_variant)]
pub enum Lookup {
    /// The file verified: the table.
    Hit(FilmTable),
    /// No file for this key.
    Miss,
    /// A file that does not verify (why): not used.
    Rejected(CacheWarning),
}

/// A directory of film tables.
#[derive(Debug, Clone, PartialEq)]
pub struct TableCache {
    dir: PathBuf,
}

static DISK_CACHE: RwLock<Option<TableCache>> = RwLock::new(None);

/// Sets the cache that [`FilmTable::shared`] reads and fills in this process (None: tables are
/// built and kept in memory only, the library's default; the command line sets it).
pub fn set_disk_cache(cache: Option<TableCache>) {
    *DISK_CACHE.write().unwrap_or_else(|e| e.into_inner()) = cache;
}

/// The cache set by [`set_disk_cache`].
pub fn disk_cache() -> Option<TableCache> {
    DISK_CACHE.read().unwrap_or_else(|e| e.into_inner()).clone()
}

impl TableCache {
    /// A cache in `dir` (created when a table is first stored).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }

    /// The default directory: `$ROTOR_TWIN_CACHE_DIR`, else `$XDG_CACHE_HOME/rotor-twin`, else
    /// `~/.cache/rotor-twin` (None without any of them).
    pub fn default_dir() -> Option<PathBuf> {
        let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
        if let Some(dir) = var("ROTOR_TWIN_CACHE_DIR") {
            return Some(PathBuf::from(dir));
        }
        // the XDG base directory specification ignores relative paths
        if let Some(xdg) = var("XDG_CACHE_HOME").map(PathBuf::from) {
            if xdg.is_absolute() {
                return Some(xdg.join("rotor-twin"));
            }
        }
        var("HOME").map(|h| PathBuf::from(h).join(".cache").join("rotor-twin"))
    }

    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The file that holds the table of these inputs.
    pub fn path_for(
        &self,
        geometry: &BearingGeometry,
        lubricant: Lubricant,
        grid: FilmGrid,
    ) -> PathBuf {
        self.path_for_slice(geometry, lubricant, grid, None)
    }

    /// [`TableCache::path_for`] for a table of flow `flow` (a turbulent slice, or laminar).
    pub fn path_for_slice(
        &self,
        geometry: &BearingGeometry,
        lubricant: Lubricant,
        grid: FilmGrid,
        flow: SliceFlow,
    ) -> PathBuf {
        let key = key_for(geometry, lubricant, grid, &TableResolution::DEFAULT, flow);
        self.dir
            .join(format!("film-table-{:x}.bin", md5::compute(key.as_bytes())))
    }

    /// The table of these inputs if its file exists and verifies.
    pub fn load(&self, geometry: &BearingGeometry, lubricant: Lubricant, grid: FilmGrid) -> Lookup {
        self.load_slice(geometry, lubricant, grid, None)
    }

    /// [`TableCache::load`] for a table of flow `flow`.
    pub fn load_slice(
        &self,
        geometry: &BearingGeometry,
        lubricant: Lubricant,
        grid: FilmGrid,
        flow: SliceFlow,
    ) -> Lookup {
        let path = self.path_for_slice(geometry, lubricant, grid, flow);
        let bytes = match std::fs::read(&path) {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Lookup::Miss,
            Err(e) => {
                return Lookup::Rejected(CacheWarning {
                    path,
                    what: format!("cannot be read ({e}); building the table"),
                })
            }
        };
        let res = TableResolution::DEFAULT;
        let key = key_for(geometry, lubricant, grid, &res, flow);
        match decode(&bytes, &key, grid, &res) {
            Ok((nodes, profiles, u_max)) => Lookup::Hit(FilmTable {
                geometry: geometry.clone(),
                lubricant,
                grid,
                flow,
                nodes,
                profiles,
                n_theta: grid.n_theta,
                res,
                layout: res.layout(),
                u_max,
                couette_factor: super::couette_factor(grid),
            }),
            Err(why) => Lookup::Rejected(CacheWarning {
                path,
                what: format!("{why}; not used, the table is rebuilt"),
            }),
        }
    }

    /// Writes `table` to its file: a temporary file in the directory, renamed over the target.
    /// Only tables of the default resolution are cached.
    pub fn store(&self, table: &FilmTable) -> Result<PathBuf, CacheWarning> {
        let path = self.path_for_slice(&table.geometry, table.lubricant, table.grid, table.flow);
        let warn = |what: String| CacheWarning {
            path: path.clone(),
            what,
        };
        if table.res != TableResolution::DEFAULT {
            return Err(warn(format!(
                "a table of resolution {:?} is not the default's; not cached",
                table.res
            )));
        }
        std::fs::create_dir_all(&self.dir).map_err(|e| {
            warn(format!(
                "cannot create the directory ({e}); table not cached"
            ))
        })?;
        let key = key_for(
            &table.geometry,
            table.lubricant,
            table.grid,
            &table.res,
            table.flow,
        );
        let bytes = encode(table, &key);
        let mut tmp = tempfile::Builder::new()
            .prefix(".film-table-")
            .suffix(".tmp")
            .tempfile_in(&self.dir)
            .map_err(|e| {
                warn(format!(
                    "cannot write in the directory ({e}); table not cached"
                ))
            })?;
        // readable by other users' twins, as a file written the usual way would be
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let readable = std::fs::Permissions::from_mode(0o644);
            tmp.as_file()
                .set_permissions(readable)
                .map_err(|e| warn(format!("cannot set the file's permissions ({e})")))?;
        }
        tmp.write_all(&bytes)
            .and_then(|()| tmp.as_file().sync_all())
            .map_err(|e| warn(format!("cannot write the table ({e}); table not cached")))?;
        tmp.persist(&path)
            .map_err(|e| warn(format!("cannot rename the written table into place ({e})")))?;
        Ok(path)
    }

    /// The table from its file, else built (waiting first for another process that builds the
    /// same table) and stored. Every cache problem goes to `warn` and is otherwise ignored; only
    /// the build's own errors are errors.
    pub fn load_or_build(
        &self,
        geometry: &BearingGeometry,
        lubricant: Lubricant,
        grid: FilmGrid,
        warn: &mut dyn FnMut(CacheWarning),
    ) -> Result<(FilmTable, TableOrigin), FilmError> {
        self.load_or_build_slice(geometry, lubricant, grid, None, warn)
    }

    /// [`TableCache::load_or_build`] for a table of flow `flow`.
    pub fn load_or_build_slice(
        &self,
        geometry: &BearingGeometry,
        lubricant: Lubricant,
        grid: FilmGrid,
        flow: SliceFlow,
        warn: &mut dyn FnMut(CacheWarning),
    ) -> Result<(FilmTable, TableOrigin), FilmError> {
        let path = self.path_for_slice(geometry, lubricant, grid, flow);
        let mut lookup = self.load_slice(geometry, lubricant, grid, flow);
        // held until the table is stored (dropped on return)
        let _lock = if matches!(lookup, Lookup::Miss) {
            let lock = self.builder_lock(&path, warn);
            // whoever held the lock may have stored the table meanwhile
            lookup = self.load_slice(geometry, lubricant, grid, flow);
            lock
        } else {
            None
        };
        match lookup {
            Lookup::Hit(table) => return Ok((table, TableOrigin::Loaded(path))),
            Lookup::Rejected(w) => warn(w),
            Lookup::Miss => {}
        }
        let table =
            FilmTable::build_slice(geometry, lubricant, grid, TableResolution::DEFAULT, flow)?;
        let stored = match self.store(&table) {
            Ok(p) => Some(p),
            Err(w) => {
                warn(w);
                None
            }
        };
        Ok((table, TableOrigin::Built(stored)))
    }

    /// An exclusive lock on `<table file>.lock` (released when dropped, or when the process
    /// ends), waiting at most [`LOCK_WAIT`] for another holder; None (building without it) if
    /// the lock cannot be had.
    fn builder_lock(
        &self,
        table_path: &Path,
        warn: &mut dyn FnMut(CacheWarning),
    ) -> Option<std::fs::File> {
        let path = table_path.with_extension("lock");
        let opened = std::fs::create_dir_all(&self.dir).and_then(|()| {
            std::fs::OpenOptions::new()
                .create(true)
                .truncate(false)
                .write(true)
                .open(&path)
        });
        let file = match opened {
            Ok(f) => f,
            Err(e) => {
                warn(CacheWarning {
                    path,
                    what: format!("cannot open the builders' lock ({e}); building without it"),
                });
                return None;
            }
        };
        let start = Instant::now();
        loop {
            match file.try_lock() {
                Ok(()) => return Some(file),
                Err(std::fs::TryLockError::WouldBlock) if start.elapsed() < LOCK_WAIT => {
                    std::thread::sleep(Duration::from_millis(50));
                }
                Err(e) => {
                    warn(CacheWarning {
                        path,
                        what: format!("builders' lock not had ({e}); building here too"),
                    });
                    return None;
                }
            }
        }
    }
}

/// Everything that determines a table of the default resolution, spelled out (f64 in Rust's
/// shortest round-trip form).
pub fn table_key(geometry: &BearingGeometry, lubricant: Lubricant, grid: FilmGrid) -> String {
    key_for(geometry, lubricant, grid, &TableResolution::DEFAULT, None)
}

/// The key of a table of resolution `res`.
fn key_for(
    geometry: &BearingGeometry,
    lubricant: Lubricant,
    grid: FilmGrid,
    res: &TableResolution,
    flow: SliceFlow,
) -> String {
    let grooves: Vec<String> = geometry
        .grooves
        .iter()
        .map(|g| {
            format!(
                "{:?}/{:?}/{:?}",
                g.center_rad, g.width_rad, g.supply_pressure_pa
            )
        })
        .collect();
    format!(
        "rotor-twin film table\nformat {FORMAT_VERSION}\nsolver {SOLVER_VERSION} source {:x}\n\
         nodes {}x{} map {:?} eps_max {:?} eps_row_cap {:?} grid_phases {}\nwall rows {}\n\
         diameter_m {:?}\nlength_m {:?}\nradial_clearance_m {:?}\ngrooves [{}]\n\
         density_kg_m3 {:?}\nviscosity_pa_s {:?}\ngrid {}x{}\n",
        source_fingerprint(),
        res.n_ecc,
        res.n_psi,
        res.map,
        MAX_ECCENTRICITY_RATIO,
        ROW_ECC_CAP,
        res.grid_phases,
        res.wall.map_or("none".into(), |w| format!(
            "eps >= {}/1000: {} columns, grid_phases {}",
            w.from_ecc_per_mille, w.n_psi, w.grid_phases
        )),
        geometry.diameter_m,
        geometry.length_m,
        geometry.radial_clearance_m,
        grooves.join(","),
        lubricant.density_kg_m3,
        lubricant.viscosity_pa_s,
        grid.n_theta,
        grid.n_z,
    ) + &flow.map_or(String::new(), |(regime, reynolds)| {
        format!("flow {regime:?} reynolds {reynolds:?}\n")
    })
}

/// MD5 of the source files that compute a table's numbers (the finite solver, its band
/// factor, the table builder): a change to any of them makes every key new.
fn source_fingerprint() -> md5::Digest {
    let mut ctx = md5::Context::new();
    for src in TABLE_SOURCES {
        ctx.consume(src.as_bytes());
    }
    ctx.finalize()
}

pub(super) fn node_values(n: &Node) -> [f64; NODE_VALUES] {
    let a = &n.angles;
    [
        n.force[0],
        n.force[1],
        n.p_max,
        a[0][0],
        a[0][1],
        a[1][0],
        a[1][1],
        a[2][0],
        a[2][1],
        n.torque_pressure,
        n.torque_couette,
        n.side_flow,
        n.inflow_pressure,
        n.inflow_couette,
    ]
}

fn node_from(v: &[f64]) -> Node {
    Node {
        force: [v[0], v[1]],
        p_max: v[2],
        angles: [[v[3], v[4]], [v[5], v[6]], [v[7], v[8]]],
        torque_pressure: v[9],
        torque_couette: v[10],
        side_flow: v[11],
        inflow_pressure: v[12],
        inflow_couette: v[13],
    }
}

/// Payload bytes of a table of resolution `res` with `n_theta` profile angles.
fn payload_len(n_theta: usize, res: &TableResolution) -> usize {
    res.nodes() * (NODE_VALUES + n_theta) * 8
}

fn encode(table: &FilmTable, key: &str) -> Vec<u8> {
    let mut payload = Vec::with_capacity(payload_len(table.n_theta, &table.res));
    for n in &table.nodes {
        for v in node_values(n) {
            payload.extend_from_slice(&v.to_le_bytes());
        }
    }
    for v in &table.profiles {
        payload.extend_from_slice(&v.to_le_bytes());
    }
    let mut out = Vec::with_capacity(payload.len() + key.len() + 64);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&(key.len() as u32).to_le_bytes());
    out.extend_from_slice(key.as_bytes());
    out.extend_from_slice(&(table.n_theta as u32).to_le_bytes());
    out.extend_from_slice(&table.u_max.to_le_bytes());
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
    out.extend_from_slice(&payload);
    out
}

/// Reads little-endian fields off the front of a byte slice; runs out with an error.
struct Fields<'a>(&'a [u8]);

impl<'a> Fields<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], String> {
        if self.0.len() < n {
            return Err(format!("file ends inside the {what} (truncated)"));
        }
        let (head, rest) = self.0.split_at(n);
        self.0 = rest;
        Ok(head)
    }
    fn u32(&mut self, what: &str) -> Result<u32, String> {
        let b = self.take(4, what)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    fn u64(&mut self, what: &str) -> Result<u64, String> {
        let b = self.take(8, what)?;
        Ok(u64::from_le_bytes(b.try_into().unwrap_or_default()))
    }
}

/// The nodes, profiles and u_max of a file, if it holds the table of `key` on `grid` intact.
fn decode(
    bytes: &[u8],
    key: &str,
    grid: FilmGrid,
    res: &TableResolution,
) -> Result<(Vec<Node>, Vec<f64>, f64), String> {
    let mut f = Fields(bytes);
    if f.take(MAGIC.len(), "magic number")? != MAGIC {
        return Err("not a film table file (magic number)".into());
    }
    let version = f.u32("format version")?;
    if version != FORMAT_VERSION {
        return Err(format!(
            "format version {version}, expected {FORMAT_VERSION}"
        ));
    }
    let key_len = f.u32("key length")? as usize;
    if f.take(key_len, "key")? != key.as_bytes() {
        return Err("written for other inputs (key differs)".into());
    }
    let n_theta = f.u32("profile size")? as usize;
    let u_max = f64::from_le_bytes(f.u64("table domain")?.to_le_bytes());
    let expected_u_max = res.map.u(MAX_ECCENTRICITY_RATIO);
    if n_theta != grid.n_theta || u_max.to_bits() != expected_u_max.to_bits() {
        return Err(format!(
            "header n_θ {n_theta}, u_max {u_max} do not match the key"
        ));
    }
    let len = f.u64("payload length")?;
    let crc = f.u32("checksum")?;
    let needed = payload_len(n_theta, res);
    if len != needed as u64 || f.0.len() as u64 != len {
        return Err(format!(
            "payload of {} bytes, header says {len}, the table needs {}",
            f.0.len(),
            needed
        ));
    }
    if crc32fast::hash(f.0) != crc {
        return Err("checksum (CRC-32) does not match: damaged".into());
    }
    let values: Vec<f64> =
        f.0.chunks_exact(8)
            .map(|b| f64::from_le_bytes(b.try_into().unwrap_or_default()))
            .collect();
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(format!("value {i} is not finite"));
    }
    let (node_part, profiles) = values.split_at(res.nodes() * NODE_VALUES);
    let nodes = node_part.chunks_exact(NODE_VALUES).map(node_from).collect();
    Ok((nodes, profiles.to_vec(), u_max))
}
