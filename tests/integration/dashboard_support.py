"""The Grafana dashboard of deploy/grafana: its PromQL expressions and the metric names they use."""

import json
import re
from pathlib import Path

DASHBOARD = Path(__file__).resolve().parents[2] / "deploy" / "grafana" / "rsg-fleet.json"

# PromQL words that are not metric names.
_KEYWORDS = {"by", "without", "on", "ignoring", "group_left", "group_right", "bool", "and", "or", "unless",
             "offset", "inf", "nan"}
_GRAFANA_VARIABLES = {"$gateway": ".*", "$__rate_interval": "5s", "$__interval": "5s"}


def _expressions(dashboard):
    for panel in dashboard["panels"]:
        for target in panel.get("targets", []):
            yield target["expr"]


def dashboard_expressions(for_prometheus=False):
    """Every panel's expression; with Grafana's variables replaced by values when `for_prometheus`."""
    dashboard = json.loads(DASHBOARD.read_text())
    expressions = list(_expressions(dashboard))
    if for_prometheus:
        for variable, value in _GRAFANA_VARIABLES.items():
            expressions = [e.replace(variable, value) for e in expressions]
    return expressions


def metric_names(expression):
    """The metric names an expression selects: identifiers outside strings, label matchers, ranges and
    grouping clauses that are not followed by '(' (functions, aggregations) and are not keywords."""
    text = re.sub(r'"(?:[^"\\]|\\.)*"', '""', expression)
    text = re.sub(r"\{[^}]*\}", "", text)
    text = re.sub(r"\[[^\]]*\]", "", text)
    text = re.sub(r"\b(by|without|on|ignoring|group_left|group_right)\s*\([^)]*\)", "", text)
    names = set()
    for match in re.finditer(r"[a-zA-Z_:][a-zA-Z0-9_:]*", text):
        rest = text[match.end():].lstrip()
        if rest.startswith("(") or match.group(0).lower() in _KEYWORDS:
            continue
        if match.start() > 0 and text[match.start() - 1] in "$0123456789.":
            continue
        names.add(match.group(0))
    return names


def dashboard_metric_names():
    """{metric name: [expressions naming it]} over every panel and the templating queries."""
    dashboard = json.loads(DASHBOARD.read_text())
    used = {}
    for expression in _expressions(dashboard):
        for name in metric_names(expression):
            used.setdefault(name, []).append(expression)
    for variable in dashboard.get("templating", {}).get("list", []):
        query = variable.get("query")
        query = query.get("query", "") if isinstance(query, dict) else (query or "")
        match = re.match(r"\s*label_values\(\s*([a-zA-Z_:][a-zA-Z0-9_:]*)", query)
        if match:
            used.setdefault(match.group(1), []).append(query)
    return used
