//! `rotor-twin node`: the live ROS 2 node.

use std::path::PathBuf;

/// The live ROS 2 node (run it inside a private network namespace on shared machines).
#[derive(Debug, Clone, clap::Parser)]
pub struct NodeArgs {
    /// Machine description (YAML); the built-in ORC microturbine if absent.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Record every input and output into this new bag directory (rosbag2 MCAP).
    #[arg(long)]
    record: Option<PathBuf>,
    /// Largest file of the recording (bytes) before it goes on in the next, DIR_1.mcap, …
    /// (rosbag2's --max-bag-size); 0: no limit. Default 268435456 (256 MiB).
    #[arg(long)]
    record_max_bag_size: Option<u64>,
    /// Longest span of receive times in one file of the recording (s; rosbag2's
    /// --max-bag-duration); 0 (the default): no limit.
    #[arg(long)]
    record_max_bag_duration: Option<f64>,
    /// ROS arguments: -p name:=value, --params-file F.yaml, -r from:=to.
    #[arg(long = "ros-args", num_args = 0.., allow_hyphen_values = true)]
    ros_args: Vec<String>,
}

pub(crate) fn run(args: NodeArgs) -> anyhow::Result<()> {
    crate::ros::run(setup(args)?)
}

/// The node's setup; the node's own options may also follow the ROS arguments after `--`, as
/// `ros2 run` passes them (`node --ros-args -p a:=b -- --record DIR`).
fn setup(mut args: NodeArgs) -> anyhow::Result<crate::ros::NodeSetup> {
    if let Some(end) = args.ros_args.iter().position(|a| a == "--") {
        let rest: Vec<String> = args.ros_args.split_off(end).into_iter().skip(1).collect();
        let tail = <NodeArgs as clap::Parser>::try_parse_from(
            std::iter::once("node".to_string()).chain(rest),
        )?;
        anyhow::ensure!(
            !(tail.config.is_some() && args.config.is_some()
                || tail.record.is_some() && args.record.is_some()),
            "--config or --record given twice (before --ros-args and after --)"
        );
        args.config = args.config.or(tail.config);
        args.record = args.record.or(tail.record);
        args.record_max_bag_size = args.record_max_bag_size.or(tail.record_max_bag_size);
        args.record_max_bag_duration = args
            .record_max_bag_duration
            .or(tail.record_max_bag_duration);
        args.ros_args.extend(tail.ros_args);
    }
    let record_split = crate::record::SplitLimits::from_options(
        args.record_max_bag_size
            .unwrap_or(crate::record::DEFAULT_MAX_BAGFILE_BYTES),
        args.record_max_bag_duration.unwrap_or(0.0),
    )
    .map_err(anyhow::Error::msg)?;
    Ok(crate::ros::NodeSetup {
        config: args.config,
        record: args.record,
        record_split,
        ros_args: args.ros_args,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Debug, Parser)]
    struct Top {
        #[command(flatten)]
        node: NodeArgs,
    }

    #[test]
    fn node_options_after_the_ros_arguments_are_kept() {
        // `node --ros-args … -- --record DIR` used to drop --record silently
        let top = Top::try_parse_from([
            "node",
            "--ros-args",
            "-p",
            "model:=linear",
            "--",
            "--record",
            "run1",
        ])
        .unwrap();
        let s = setup(top.node).unwrap();
        assert_eq!(s.record, Some(PathBuf::from("run1")));
        assert_eq!(s.ros_args, ["-p", "model:=linear"]);
        assert_eq!(s.record_split, crate::record::SplitLimits::default());
    }

    #[test]
    fn the_recording_split_options_are_taken_and_checked() {
        let parse = |args: &[&str]| {
            let all = ["node"].iter().chain(args).copied();
            setup(Top::try_parse_from(all).unwrap().node)
        };
        let s = parse(&["--ros-args", "--", "--record-max-bag-duration", "60"]).unwrap();
        assert_eq!(s.record_split.max_duration_ns, Some(60_000_000_000));
        assert_eq!(
            s.record_split.max_bytes,
            Some(crate::record::DEFAULT_MAX_BAGFILE_BYTES)
        );
        let s = parse(&["--record-max-bag-size", "0"]).unwrap();
        assert_eq!(s.record_split.max_bytes, None);
        let e = parse(&["--record-max-bag-size", "10"]).unwrap_err();
        assert!(e.to_string().contains("--record-max-bag-size 10"), "{e}");
    }
}

/// `rotor-twin param`: a running node's parameters, through its ROS 2 parameter services (run
/// it in the node's network namespace).
#[derive(Debug, Clone, clap::Args)]
pub struct ParamArgs {
    /// The node.
    #[arg(long, default_value = "/rotor_twin")]
    node: String,
    /// Seconds to wait for the node's answer.
    #[arg(long, default_value_t = 10.0)]
    timeout: f64,
    #[command(subcommand)]
    call: ParamCommand,
}

#[derive(Debug, Clone, clap::Subcommand)]
enum ParamCommand {
    /// Print parameters' values.
    Get {
        /// Parameter names.
        #[arg(required = true)]
        names: Vec<String>,
    },
    /// Set parameters: NAME:=VALUE (a start-only parameter is refused with the node's reason).
    Set {
        /// NAME:=VALUE assignments.
        #[arg(required = true, value_parser = parse_assignment)]
        assignments: Vec<(String, String)>,
    },
}

fn parse_assignment(s: &str) -> Result<(String, String), String> {
    let (name, value) = s
        .split_once(":=")
        .ok_or_else(|| format!("'{s}': expected NAME:=VALUE"))?;
    if name.is_empty() {
        return Err(format!("'{s}': missing parameter name"));
    }
    Ok((name.into(), value.into()))
}

pub(crate) fn run_param(args: ParamArgs) -> anyhow::Result<()> {
    anyhow::ensure!(
        args.timeout.is_finite() && args.timeout > 0.0,
        "--timeout {}: must be positive (s)",
        args.timeout
    );
    let call = match args.call {
        ParamCommand::Get { names } => crate::ros::ParamCall::Get(names),
        ParamCommand::Set { assignments } => crate::ros::ParamCall::Set(assignments),
    };
    crate::ros::param_call(
        &args.node,
        call,
        std::time::Duration::from_secs_f64(args.timeout),
    )
}
