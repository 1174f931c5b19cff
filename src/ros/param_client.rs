//! `rotor-twin param`: get and set a running node's ROS 2 parameters through its parameter
//! services (rcl_interfaces GetParameters / SetParameters), as `ros2 param get|set` does.

use ros2_client::qos::History;
use ros2_client::rcl_interfaces::{
    GetParametersRequest, GetParametersResponse, SetParametersRequest, SetParametersResponse,
};
use ros2_client::{
    Client, Context, Name, NodeName, NodeOptions, Parameter, ParameterValue, QosProfile,
    ServiceMapping, ServiceTypeName,
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
        let peer = Peer { node, timeout };
        let getter: Client<GetParametersRequest, GetParametersResponse> = peer
            .client(&mut me, "get_parameters", "GetParameters")
            .await?;
        let result = match call {
            ParamCall::Get(names) => {
                let values = peer.get(&getter, names.clone()).await?;
                for (name, value) in names.iter().zip(values) {
                    println!("{name}: {}", shown(&value));
                }
                Ok(())
            }
            ParamCall::Set(items) => {
                let setter: Client<SetParametersRequest, SetParametersResponse> = peer
                    .client(&mut me, "set_parameters", "SetParameters")
                    .await?;
                let current = peer
                    .get(&getter, items.iter().map(|(n, _)| n.clone()).collect())
                    .await?;
                let request = set_request(&items, &current);
                let response = peer.call(&setter, request, "set_parameters").await?;
                let outcomes = response.results.iter();
                report_set(&items, outcomes.map(|r| (r.successful, r.reason.as_str())))
            }
        };
        // A one-shot command: the DDS participant is not dropped. RustDDS 0.15's teardown can
        // run its last drop on its own discovery thread, which then joins itself and panics
        // ("failed to join thread: Resource deadlock avoided", seen once in node_namespaces
        // after a correct answer); the process ends right after, and the OS frees the rest.
        std::mem::forget(me);
        std::mem::forget(context);
        result
    })
}

/// How long a parameter request waits for its answer before it is sent again
/// ([`Peer::call`]).
const RESEND_PERIOD: Duration = Duration::from_secs(3);

/// The node whose parameter services are called, and how long it may take to answer.
struct Peer<'a> {
    node: &'a str,
    timeout: Duration,
}

impl Peer<'_> {
    /// A client of the node's service `service` (type rcl_interfaces/`type_name`), once the
    /// service is there.
    async fn client<Req, Resp>(
        &self,
        me: &mut ros2_client::Node,
        service: &'static str,
        type_name: &str,
    ) -> anyhow::Result<Client<Req, Resp>>
    where
        Req: ros2_client::Message + Clone + 'static,
        Resp: ros2_client::Message + 'static,
    {
        // the QoS ros2-client's parameter servers use
        let qos = QosProfile::publisher_default().history(History::KeepLast { depth: 1 });
        let name = Name::new(self.node, service)
            .map_err(|e| anyhow::anyhow!("node name '{}': {e:?}", self.node))?;
        let client = me
            .create_client::<Req, Resp>(
                ServiceMapping::Enhanced,
                &name,
                &ServiceTypeName::new("rcl_interfaces", type_name),
                qos.clone(),
                qos,
            )
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        tokio::time::timeout(self.timeout, client.wait_for_service(me))
            .await
            .map_err(|_| self.late(service))?;
        Ok(client)
    }

    /// One request and its response. The request is sent again every [`RESEND_PERIOD`] until
    /// an answer comes or the timeout ends: `wait_for_service` returns once *our* request
    /// writer and response reader have matched the node's, but the node's response writer may
    /// not yet have matched our reader, and a response sent then is lost (seen once in CI on a
    /// loaded machine: the node logged no refusal, the client waited its 30 s). Each of the
    /// node's parameter services is idempotent (a get; a set of the same values).
    async fn call<Req, Resp>(
        &self,
        client: &Client<Req, Resp>,
        request: Req,
        service: &'static str,
    ) -> anyhow::Result<Resp>
    where
        Req: ros2_client::Message + Clone + 'static,
        Resp: ros2_client::Message + 'static,
    {
        let deadline = tokio::time::Instant::now() + self.timeout;
        loop {
            let id = client
                .async_send_request(request.clone())
                .await
                .map_err(|e| anyhow::anyhow!("{e:?}"))?;
            let left = deadline.saturating_duration_since(tokio::time::Instant::now());
            let wait = RESEND_PERIOD.min(left);
            match tokio::time::timeout(wait, client.async_receive_response(id)).await {
                Ok(response) => return response.map_err(|e| anyhow::anyhow!("{e:?}")),
                Err(_) if tokio::time::Instant::now() >= deadline => return Err(self.late(service)),
                Err(_) => continue,
            }
        }
    }

    /// The values of parameters `names`.
    async fn get(
        &self,
        getter: &Client<GetParametersRequest, GetParametersResponse>,
        names: Vec<String>,
    ) -> anyhow::Result<Vec<ParameterValue>> {
        let response = self
            .call(getter, GetParametersRequest { names }, "get_parameters")
            .await?;
        Ok(response
            .values
            .into_iter()
            .map(ParameterValue::from)
            .collect())
    }

    fn late(&self, service: &str) -> anyhow::Error {
        anyhow::anyhow!(
            "node {} did not answer {service} within {:?}",
            self.node,
            self.timeout
        )
    }
}

/// The set request for `items` (name, value as text); a whole number given for a parameter that
/// is a double now (`current`) is meant as a double.
fn set_request(items: &[(String, String)], current: &[ParameterValue]) -> SetParametersRequest {
    SetParametersRequest {
        parameter: items
            .iter()
            .zip(current)
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
    }
}

/// Prints each set's outcome (successful, reason); Err naming the refused ones.
fn report_set<'a>(
    items: &[(String, String)],
    outcomes: impl Iterator<Item = (bool, &'a str)>,
) -> anyhow::Result<()> {
    let mut refused = Vec::new();
    for ((name, value), (successful, reason)) in items.iter().zip(outcomes) {
        if successful {
            println!("{name}:={value}: set");
        } else {
            println!("{name}:={value}: REFUSED: {reason}");
            refused.push(name.clone());
        }
    }
    anyhow::ensure!(refused.is_empty(), "refused: {}", refused.join(", "));
    Ok(())
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
