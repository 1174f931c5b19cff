//! The film-table disk cache (`src/film/table/cache.rs`): a table read back is the table built,
//! bit for bit; a damaged or foreign file is reported and rebuilt, never used; other inputs miss;
//! concurrent writers and builders leave one valid file. Every cache lives in a temporary
//! directory. Tables on the coarsest grid the solver accepts (12 × 2), so that a build takes
//! about a second: the cache does not look at the numbers, only stores them.

use rotor_twin::film::{
    table_key, BearingGeometry, CacheWarning, FilmGrid, FilmModel, FilmTable, JournalKinematics,
    Lookup, Lubricant, TableCache, TableOrigin, TableResolution, TabulatedFilm,
};
use std::sync::Arc;

fn bearing() -> (BearingGeometry, Lubricant, FilmGrid) {
    (
        BearingGeometry::plain(0.06, 0.03, 40e-6).unwrap(),
        Lubricant::new(900.0, 0.0008).unwrap(),
        FilmGrid::new(12, 2).unwrap(),
    )
}

/// A table built into a fresh cache directory: (directory, cache, table, its file).
fn built() -> (tempfile::TempDir, TableCache, FilmTable, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let cache = TableCache::new(dir.path().join("tables"));
    let (g, l, grid) = bearing();
    let mut warnings = Vec::new();
    let (table, origin) = cache
        .load_or_build(&g, l, grid, &mut |w| warnings.push(w))
        .unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let TableOrigin::Built(Some(path)) = origin else {
        panic!("an empty cache builds and stores: {origin:?}");
    };
    (dir, cache, table, path)
}

fn same_bits(a: &FilmTable, b: &FilmTable) -> bool {
    let (va, vb) = (a.values(), b.values());
    va.len() == vb.len() && va.iter().zip(&vb).all(|(x, y)| x.to_bits() == y.to_bits())
}

fn load(cache: &TableCache) -> Lookup {
    let (g, l, grid) = bearing();
    cache.load(&g, l, grid)
}

/// States across the table: near the centre, in the whip domain with whirl and squeeze
/// velocities, near the wall (ε, attitude, v_r / cω, v_t / cω).
fn states() -> Vec<JournalKinematics> {
    let (c, w) = (40e-6, 942.5);
    [
        (0.0005, 0.3, 0.0, 0.0),
        (0.3, 0.4, 0.01, -0.02),
        (0.6, 2.0, -0.05, 0.1),
        (0.85, 4.0, 0.2, 0.05),
        (0.98, 5.5, -0.1, -0.2),
    ]
    .into_iter()
    .map(|(e, phi, vr, vt): (f64, f64, f64, f64)| {
        let (vr, vt) = (vr * c * w, vt * c * w);
        JournalKinematics {
            position_m: [e * c * phi.cos(), e * c * phi.sin()],
            velocity_m_s: [
                vr * phi.cos() - vt * phi.sin(),
                vr * phi.sin() + vt * phi.cos(),
            ],
            speed_rad_s: w,
        }
    })
    .collect()
}

#[test]
fn a_table_read_back_is_the_table_built_bit_for_bit_with_identical_film_forces() {
    let (_dir, cache, table, path) = built();
    let Lookup::Hit(loaded) = load(&cache) else {
        panic!("the stored table must load from {}", path.display());
    };
    // 62 rows of 192 columns, then the 98 rows at ε ≥ 0.90 of 384 (`WallRows`), 14 values a
    // node and the 12-angle profile
    assert_eq!(TableResolution::DEFAULT.nodes(), 62 * 192 + 98 * 384);
    assert_eq!(table.values().len(), (62 * 192 + 98 * 384) * (14 + 12));
    assert!(same_bits(&table, &loaded), "a tabulated value differs");
    // what the twin reads: force, zone, friction, flows, the eight coefficients, the profile
    let (mut a, mut b) = (
        TabulatedFilm::new(Arc::new(table)),
        TabulatedFilm::new(Arc::new(loaded)),
    );
    for kin in states() {
        let (ra, ca) = a.solve_with_coefficients(&kin).unwrap();
        let (rb, cb) = b.solve_with_coefficients(&kin).unwrap();
        assert_eq!(format!("{ra:?}"), format!("{rb:?}"));
        assert_eq!(format!("{ca:?}"), format!("{cb:?}"));
        assert!(ra.force_n[0].to_bits() == rb.force_n[0].to_bits() && ra.force_n[0] != 0.0);
        let (mut pa, mut pb) = ([0.0; 36], [0.0; 36]);
        a.midplane_pressure(&mut pa);
        b.midplane_pressure(&mut pb);
        assert!(pa.iter().zip(&pb).all(|(x, y)| x.to_bits() == y.to_bits()));
    }
}

#[test]
fn a_damaged_file_is_refused_and_rebuilt_with_a_warning() {
    let (_dir, cache, table, path) = built();
    let good = std::fs::read(&path).unwrap();
    let refused = |bytes: &[u8], why: &str| {
        std::fs::write(&path, bytes).unwrap();
        match load(&cache) {
            Lookup::Rejected(w) => assert!(w.what.contains(why), "{why}: {w}"),
            Lookup::Hit(_) => panic!("{why}: a damaged file was used"),
            Lookup::Miss => panic!("{why}: the file was not seen"),
        }
    };
    // one byte flipped in the last value, in the middle, in the key; cut short; emptied
    let mut last = good.clone();
    *last.last_mut().unwrap() ^= 0x01;
    refused(&last, "checksum");
    let mut middle = good.clone();
    middle[good.len() / 2] ^= 0x80;
    refused(&middle, "checksum");
    let mut key = good.clone();
    key[20] ^= 0x20;
    refused(&key, "key differs");
    refused(&good[..good.len() - 1], "payload of");
    refused(&good[..100], "truncated");
    refused(&[], "truncated");
    // the rebuild: one warning naming the file, then a file that loads and equals the original
    std::fs::write(&path, &middle).unwrap();
    let (g, l, grid) = bearing();
    let mut warnings: Vec<CacheWarning> = Vec::new();
    let (rebuilt, origin) = cache
        .load_or_build(&g, l, grid, &mut |w| warnings.push(w))
        .unwrap();
    assert_eq!(origin, TableOrigin::Built(Some(path.clone())));
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].path == path && warnings[0].what.contains("rebuilt"));
    assert!(same_bits(&rebuilt, &table));
    assert!(matches!(load(&cache), Lookup::Hit(t) if same_bits(&t, &table)));
}

#[test]
fn other_inputs_miss_and_a_file_of_other_inputs_is_refused() {
    let (_dir, cache, _table, path) = built();
    let (g, l, grid) = bearing();
    let clearance = BearingGeometry::plain(0.06, 0.03, 41e-6).unwrap();
    let length = BearingGeometry::plain(0.06, 0.031, 40e-6).unwrap();
    let grid_z = FilmGrid::new(12, 3).unwrap();
    let grid_theta = FilmGrid::new(13, 2).unwrap();
    let oil = Lubricant::new(900.0, 0.00081).unwrap();
    let others = [
        (clearance.clone(), l, grid),
        (length, l, grid),
        (g.clone(), l, grid_z),
        (g.clone(), l, grid_theta),
        (g.clone(), oil, grid),
    ];
    for (og, ol, ogrid) in &others {
        assert_ne!(cache.path_for(og, *ol, *ogrid), path);
        assert!(matches!(cache.load(og, *ol, *ogrid), Lookup::Miss));
    }
    // the right name with the wrong content (a file copied over another): the header's key
    std::fs::copy(&path, cache.path_for(&clearance, l, grid)).unwrap();
    match cache.load(&clearance, l, grid) {
        Lookup::Rejected(w) => assert!(w.what.contains("key differs"), "{w}"),
        _ => panic!("a table of 40 µm clearance was taken for 41 µm"),
    }
}

/// The key spells out the default resolution's wall rows (session 13: finer ψ columns on the
/// rows at ε ≥ 0.95, README "The film table's resolution"), so a file of the earlier uniform
/// table (the same `nodes 160x192` line, no wall rows) has another name and key: it is never
/// read, the table is rebuilt. On main (no wall rows) this fails.
#[test]
fn the_key_spells_out_the_wall_rows() {
    let (g, l, grid) = bearing();
    let key = table_key(&g, l, grid);
    let res = TableResolution::DEFAULT;
    let w = res.wall.expect("the default refines the wall rows");
    let line = format!(
        "wall rows eps >= {}/1000: {} columns, grid_phases {}\n",
        w.from_ecc_per_mille, w.n_psi, w.grid_phases
    );
    assert!(key.contains(&line), "{key}");
    assert!(w.n_psi > res.n_psi, "{w:?}");
}

#[test]
fn concurrent_writers_and_readers_see_only_whole_files() {
    let (_dir, cache, table, _path) = built();
    let table = Arc::new(table);
    std::thread::scope(|s| {
        for _ in 0..4 {
            let (cache, table) = (cache.clone(), table.clone());
            s.spawn(move || {
                for _ in 0..5 {
                    cache.store(&table).unwrap();
                }
            });
        }
        for _ in 0..2 {
            let (cache, table) = (cache.clone(), table.clone());
            s.spawn(move || {
                for _ in 0..10 {
                    match load(&cache) {
                        Lookup::Hit(t) => assert!(same_bits(&t, &table)),
                        Lookup::Miss => panic!("the file vanished while being replaced"),
                        Lookup::Rejected(w) => panic!("a reader saw a partial file: {w}"),
                    }
                }
            });
        }
    });
    assert!(matches!(load(&cache), Lookup::Hit(t) if same_bits(&t, &table)));
    // no temporary file left behind
    let names: Vec<_> = std::fs::read_dir(cache.dir())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert!(names.iter().all(|n| !n.ends_with(".tmp")), "{names:?}");
}

#[test]
fn concurrent_cold_starts_build_the_table_once() {
    // four twins starting at once on an empty cache: one builds, the others wait and load
    let dir = tempfile::tempdir().unwrap();
    let cache = TableCache::new(dir.path());
    let (g, l, grid) = bearing();
    let results: Vec<(FilmTable, TableOrigin)> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..4)
            .map(|_| {
                let (cache, g) = (cache.clone(), g.clone());
                s.spawn(move || cache.load_or_build(&g, l, grid, &mut |w| panic!("{w}")))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap().unwrap())
            .collect()
    });
    let built = results
        .iter()
        .filter(|(_, o)| matches!(o, TableOrigin::Built(_)))
        .count();
    assert_eq!(
        built,
        1,
        "{:?}",
        results.iter().map(|r| &r.1).collect::<Vec<_>>()
    );
    assert!(results.iter().all(|(t, _)| same_bits(t, &results[0].0)));
}

#[test]
fn an_unusable_cache_directory_is_a_warning_not_an_error() {
    // the "directory" is a regular file: nothing can be created in it (also as root)
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("not-a-directory");
    std::fs::write(&file, b"x").unwrap();
    let cache = TableCache::new(&file);
    let (g, l, grid) = bearing();
    let mut warnings = Vec::new();
    let (table, origin) = cache
        .load_or_build(&g, l, grid, &mut |w| warnings.push(w))
        .unwrap();
    assert_eq!(origin, TableOrigin::Built(None));
    assert!(!warnings.is_empty() && warnings.iter().all(|w| w.path.starts_with(&file)));
    assert!(
        warnings.iter().any(|w| w.what.contains("not cached")),
        "{warnings:?}"
    );
    assert!(table.values().iter().all(|v| v.is_finite()));
}
