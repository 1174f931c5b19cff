//! `rotor-twin param`: get and set a running node's ROS 2 parameters through its parameter
//! services (rcl_interfaces GetParameters / SetParameters), as `ros2 param get|set` does.

use ros2_client::qos::History;
use ros2_client::rcl_interfaces::{
    GetParametersRequest, GetParametersResponse, SetParametersRequest, SetParametersResponse,
};
use ros2_client::{
    Context, Name, NodeName, NodeOptions, Parameter, ParameterValue, QosProfile, ServiceMapping,
    ServiceTypeName,
};
use std::time::Duration;

/// What to do.
#[derive(Debug, Clone)]
pub enum ParamCall {
    /// Read these parameters.
    Get(Vec<String>),
    /// Set these parameters (name, value as text).
    Set(Vec<(String, String)>),
}

/// A parameter value from text: true/false, an integer, a decimal number, else a string.
fn value_of(text: &str) -> ParameterValue {
    match text {
        "true" => ParameterValue::Boolean(true),
        "false" => ParameterValue::Boolean(false),
        _ => text
            .parse::<i64>()
            .map(ParameterValue::Integer)
            .or_else(|_| text.parse::<f64>().map(ParameterValue::Double))
            .unwrap_or_else(|_| ParameterValue::String(text.into())),
    }
}

/// Calls node `node`'s parameter service; prints one line per parameter. Err if the node does
/// not answer within `timeout` or a set is refused (the node's reason is printed).
pub fn run(node: &str, call: ParamCall, timeout: Duration) -> anyhow::Result<()> {
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()?;
    runtime.block_on(async move {
        let context = Context::new().map_err(|e| anyhow::anyhow!("DDS context: {e:?}"))?;
        let mut me = context
            .new_node(
                NodeName::new("/", "rotor_twin_param").map_err(|e| anyhow::anyhow!("{e:?}"))?,
                NodeOptions::new(),
            )
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let spinner = me.spinner().map_err(|e| anyhow::anyhow!("{e:?}"))?;
        tokio::spawn(spinner.spin());
        // the QoS ros2-client's parameter servers use
        let qos = QosProfile::publisher_default().history(History::KeepLast { depth: 1 });
        let service = |name: &str| {
            Name::new(node, name).map_err(|e| anyhow::anyhow!("node name '{node}': {e:?}"))
        };
        let within = |what: &'static str| {
            anyhow::anyhow!("node {node} did not answer {what} within {timeout:?}")
        };
        let getter = me
            .create_client::<GetParametersRequest, GetParametersResponse>(
                ServiceMapping::Enhanced,
                &service("get_parameters")?,
                &ServiceTypeName::new("rcl_interfaces", "GetParameters"),
                qos.clone(),
                qos.clone(),
            )
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        tokio::time::timeout(timeout, getter.wait_for_service(&me))
            .await
            .map_err(|_| within("get_parameters"))?;
        let get = |names: Vec<String>| async {
            let id = getter
                .async_send_request(GetParametersRequest { names })
                .await
                .map_err(|e| anyhow::anyhow!("{e:?}"))?;
            let response = tokio::time::timeout(timeout, getter.async_receive_response(id))
                .await
                .map_err(|_| within("get_parameters"))?
                .map_err(|e| anyhow::anyhow!("{e:?}"))?;
            anyhow::Ok(
                response
                    .values
                    .into_iter()
                    .map(ParameterValue::from)
                    .collect::<Vec<_>>(),
            )
        };
        match call {
            ParamCall::Get(names) => {
                let values = get(names.clone()).await?;
                for (name, value) in names.iter().zip(values) {
                    println!("{name}: {}", shown(&value));
                }
                Ok(())
            }
            ParamCall::Set(items) => {
                let client = me
                    .create_client::<SetParametersRequest, SetParametersResponse>(
                        ServiceMapping::Enhanced,
                        &service("set_parameters")?,
                        &ServiceTypeName::new("rcl_interfaces", "SetParameters"),
                        qos.clone(),
                        qos,
                    )
                    .map_err(|e| anyhow::anyhow!("{e:?}"))?;
                tokio::time::timeout(timeout, client.wait_for_service(&me))
                    .await
                    .map_err(|_| within("set_parameters"))?;
                // a whole number given for a parameter that is a double is meant as a double
                let current = get(items.iter().map(|(n, _)| n.clone()).collect()).await?;
                let request = SetParametersRequest {
                    parameter: items
                        .iter()
                        .zip(&current)
                        .map(|((name, value), now)| {
                            let value = match (value_of(value), now) {
                                (ParameterValue::Integer(i), ParameterValue::Double(_)) => {
                                    ParameterValue::Double(i as f64)
                                }
                                (v, _) => v,
                            };
                            Parameter {
                                name: name.clone(),
                                value,
                            }
                            .into()
                        })
                        .collect(),
                };
                let id = client
                    .async_send_request(request)
                    .await
                    .map_err(|e| anyhow::anyhow!("{e:?}"))?;
                let response = tokio::time::timeout(timeout, client.async_receive_response(id))
                    .await
                    .map_err(|_| within("set_parameters"))?
                    .map_err(|e| anyhow::anyhow!("{e:?}"))?;
                let mut refused = Vec::new();
                for ((name, value), result) in items.iter().zip(response.results) {
                    if result.successful {
                        println!("{name}:={value}: set");
                    } else {
                        println!("{name}:={value}: REFUSED: {}", result.reason);
                        refused.push(name.clone());
                    }
                }
                anyhow::ensure!(refused.is_empty(), "refused: {}", refused.join(", "));
                Ok(())
            }
        }
    })
}

/// A parameter value as `ros2 param get` shows it: the type, then the value.
fn shown(v: &ParameterValue) -> String {
    match v {
        ParameterValue::NotSet => "not set".into(),
        ParameterValue::Boolean(b) => format!("Boolean value is: {b}"),
        ParameterValue::Integer(i) => format!("Integer value is: {i}"),
        ParameterValue::Double(d) => format!("Double value is: {d:?}"),
        ParameterValue::String(s) => format!("String value is: {s}"),
        other => format!("{other:?}"),
    }
}
