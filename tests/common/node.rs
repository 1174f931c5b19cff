//! The harness of the tests that open DDS participants (tests/node_*.rs): each runs a scenario
//! script of tests/interop/ inside a private network namespace (`unshare -n`, loopback only:
//! no participant ever in the host namespace), the scenario starting the node and its peers and
//! waiting for them, and reads back what they left in a scratch directory.

use serde_json::Value;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository's root.
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The real ROS 2 (rclpy) venv, set up on first use by tests/interop/setup-venv-ros.sh.
pub fn ros_venv() -> PathBuf {
    PathBuf::from(super::set_up_venv("setup-venv-ros.sh").trim())
}

/// One scenario's scratch directory (under the system's temporary directory, named by `tag` and
/// the test process), with what the node and its peers write there.
pub struct Scenario {
    /// The directory.
    pub out: PathBuf,
}

impl Scenario {
    /// A fresh scratch directory for the scenario `tag`.
    pub fn new(tag: &str) -> Self {
        let out = std::env::temp_dir().join(format!("rotor-twin-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&out).unwrap();
        Self { out }
    }

    /// Runs `bash tests/interop/<script> <rotor-twin binary> <args…>` inside `unshare -n`, the
    /// film tables cached with the other tests', and asserts that it succeeded.
    pub fn run<I, S>(&self, script: &str, args: I)
    where
        I: IntoIterator<Item = S>,
        S: AsRef<OsStr>,
    {
        let status = Command::new("unshare")
            .env("ROTOR_TWIN_CACHE_DIR", super::test_cache_dir())
            .args(["-n", "bash"])
            .arg(root().join("tests/interop").join(script))
            .arg(env!("CARGO_BIN_EXE_rotor-twin"))
            .args(args)
            .status()
            .expect("unshare (needs root: every DDS test runs in a private network namespace)");
        assert!(status.success(), "{script} failed");
    }

    /// The text of the file `name` the scenario left, empty if none.
    pub fn file(&self, name: &str) -> String {
        std::fs::read_to_string(self.out.join(name)).unwrap_or_default()
    }

    /// The JSON file `name`; if it does not parse, a panic that shows it and the logs
    /// `logs` (files of the scenario, e.g. node.err).
    pub fn json(&self, name: &str, logs: &[&str]) -> Value {
        let text = self.file(name);
        serde_json::from_str(&text).unwrap_or_else(|e| {
            let logs: String = logs
                .iter()
                .map(|l| format!("\n{l}:\n{}", self.file(l)))
                .collect();
            panic!("{name}: {e}: '{text}'{logs}")
        })
    }

    /// The recording `bag` under the directory as two independent readers (rosbags and
    /// mcap-ros2-support, tests/interop/read_bag.py) see it.
    pub fn read_bag(&self, bag: &str) -> Value {
        super::interop_json("read_bag.py", [self.out.join(bag)])
    }

    /// Removes the directory (a failed test leaves it for a look).
    pub fn remove(self) {
        std::fs::remove_dir_all(&self.out).ok();
    }
}
