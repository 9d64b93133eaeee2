"""deploy/grafana/rsg-fleet.json and deploy/prometheus/rsg-alerts.yml name only metrics the gateway
exports: every metric name in every panel's PromQL (and in the gateway variable's label_values) and
in every alert rule is in a scrape of a running gateway's /metrics. The dashboard can be provisioned
from its file: no import-time input (`${DS_PROMETHEUS}`), its data source is a variable. A gateway
without --name or --partition still labels its series `gateway` (the host's name), so that the
dashboard's variable lists it. That the expressions are valid PromQL is
integration.metrics_prometheus's part, the rules' own tests deploy.alert_rules'."""

import json
import re
import socket
import sys

from dashboard_support import DASHBOARD, dashboard_metric_names, metric_names
from harness import check, main
from metrics_support import http_get, parse_samples, start_gateway

RULES = DASHBOARD.parents[1] / "prometheus" / "rsg-alerts.yml"
# Series Prometheus makes of every target itself, which no scrape holds (RsgGatewayDown's `up`).
PROMETHEUS_SERIES = {"up"}


def rule_expressions():
    """The `expr:` of every rule (the file is written one expression per line)."""
    return re.findall(r"^\s*expr:\s*(.+)$", RULES.read_text(), re.MULTILINE)


def body(h):
    # The parser of metric names, on the shapes the dashboard uses.
    check(metric_names('sum by (gateway, category) (rate(rsg_frames_invalid_total{gateway=~"$gateway"}[$__rate_interval]))')
          == {"rsg_frames_invalid_total"}, "metric_names() misreads an aggregation")
    check(metric_names("rate(a_total[5m]) / on(gateway) b") == {"a_total", "b"}, "metric_names() misreads a join")

    # Provisionable from the file: Grafana's file provisioning fills no __inputs.
    text = DASHBOARD.read_text()
    dashboard = json.loads(text)
    check("__inputs" not in dashboard and "${DS_" not in text,
          "the dashboard needs an import-time input (${DS_...}), which file provisioning never fills")
    variables = {v["name"]: v for v in dashboard["templating"]["list"]}
    check(variables.get("datasource", {}).get("type") == "datasource", "no `datasource` variable in the dashboard")
    sources = re.findall(r'"datasource":\s*\{[^}]*"uid":\s*"([^"]*)"', text)
    check(sources and all(uid == "${datasource}" for uid in sources),
          f"panels not on the datasource variable: {sorted(set(sources))}")

    # No --name, no --partition, a flight recorder (its family is only there with one).
    gateway, _, _, metrics = start_gateway(h, "gateway", "--pcap-ring", "1", "--pcap-dir", str(h.dir))
    status, text = http_get(metrics, "/metrics")
    check(status == 200, f"/metrics answered {status}")
    samples = parse_samples(text)
    unlabelled = sorted({name for name, labels, _ in samples if labels.get("gateway") != socket.gethostname()})
    check(not unlabelled, f"series without gateway=\"{socket.gethostname()}\" (the host's name): {unlabelled}")
    exported = {name for name, _, _ in samples}
    used = dashboard_metric_names()
    check(len(used) >= 10, f"only {len(used)} metric names found in the dashboard: is the parser broken?")
    unknown = {name: expressions for name, expressions in used.items() if name not in exported}
    check(not unknown, f"the dashboard uses metrics the gateway does not export: {unknown}")
    rules = rule_expressions()
    check(len(rules) >= 4, f"only {len(rules)} alert expressions found in {RULES.name}")
    unknown = {name: e for e in rules for name in metric_names(e) if name not in exported | PROMETHEUS_SERIES}
    check(not unknown, f"the alert rules use metrics the gateway does not export: {unknown}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("grafana_dashboard", body))
