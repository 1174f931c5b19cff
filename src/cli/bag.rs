//! `rotor-twin bag`: tools for recorded bags.

use clap::{Args, Subcommand};
use std::path::PathBuf;

/// Arguments of `rotor-twin bag`.
#[derive(Debug, Args)]
pub struct BagArgs {
    #[command(subcommand)]
    command: BagCommand,
}

#[derive(Debug, Subcommand)]
enum BagCommand {
    /// A recording cut off (killed, full disk) or damaged, made a complete bag again (like
    /// `ros2 bag reindex`): every intact message into a NEW bag directory that rosbags and
    /// indexed MCAP readers open. The input is not changed.
    Recover {
        /// The bag directory (or .mcap file) to recover.
        bag: PathBuf,
        /// The new bag directory (must not exist). Default: BAG_recovered beside the input.
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

/// Runs `rotor-twin bag`.
pub fn run(args: &BagArgs) -> anyhow::Result<()> {
    match &args.command {
        BagCommand::Recover { bag, out } => {
            let out = out.clone().unwrap_or_else(|| {
                let mut name = bag.file_name().unwrap_or_default().to_os_string();
                name.push("_recovered");
                bag.with_file_name(name)
            });
            let r = crate::record::recover(bag, &out)?;
            for d in &r.damage {
                eprintln!("warning: {d}");
            }
            for n in &r.notes {
                eprintln!("warning: {}: {n}", bag.display());
            }
            let total: u64 = r.counts.iter().map(|c| c.1).sum();
            outln!("recovered {total} messages into {}", r.dir.display());
            for (topic, n) in &r.counts {
                outln!("  {topic}: {n} messages");
            }
            Ok(())
        }
    }
}
