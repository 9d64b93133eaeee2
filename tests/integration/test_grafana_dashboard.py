"""deploy/grafana/rsg-fleet.json names only metrics the gateway exports: every metric name in every
panel's PromQL (and in the gateway variable's label_values) is in a scrape of a running gateway's
/metrics. That the expressions are valid PromQL is integration.metrics_prometheus's part."""

import sys

from dashboard_support import dashboard_metric_names, metric_names
from harness import check, main
from metrics_support import http_get, parse_samples, start_gateway


def body(h):
    # The parser of metric names, on the shapes the dashboard uses.
    check(metric_names('sum by (gateway, category) (rate(rsg_frames_invalid_total{gateway=~"$gateway"}[$__rate_interval]))')
          == {"rsg_frames_invalid_total"}, "metric_names() misreads an aggregation")
    check(metric_names("rate(a_total[5m]) / on(gateway) b") == {"a_total", "b"}, "metric_names() misreads a join")

    gateway, _, _, metrics = start_gateway(h, "gateway", "--name", "robot1")
    status, text = http_get(metrics, "/metrics")
    check(status == 200, f"/metrics answered {status}")
    exported = {name for name, _, _ in parse_samples(text)}
    used = dashboard_metric_names()
    check(len(used) >= 10, f"only {len(used)} metric names found in the dashboard: is the parser broken?")
    unknown = {name: expressions for name, expressions in used.items() if name not in exported}
    check(not unknown, f"the dashboard uses metrics the gateway does not export: {unknown}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("grafana_dashboard", body))
