"""A real ROS 2 node (rclpy on rmw_fastrtps_cpp) for the rclpy tests: run with the Python of the
project's ROS 2 environment (ros2/env.sh), never imported by the tests themselves.

  sub TOPIC TYPE --qos default|sensor_data|transient_local [--depth N] [--count N] [--timeout S]
      [--idle S] [--filter EXPR [--param P ...]]
      prints every message as one JSON line on stdout (members by name, arrays as lists), "matched N"
      on stderr when the subscription matches N publishers (rmw's matched event), and exits 0 after
      --count messages (or, with --count 0, when --idle seconds pass without one after the first)
  pub TOPIC TYPE --file JSONL [--wait-subscribers N] [--period S]
      publishes one message per line of the file (members by name, like sub prints them) once it
      matched N subscriptions, then waits until they acknowledged everything
  graph TOPIC... [--wait-publishers N] [--subscriptions] [--timeout S]
      prints, per topic, what `ros2 topic info -v` shows: get_publishers_info_by_topic (or with
      --subscriptions get_subscriptions_info_by_topic) as JSON
  churn --count N --topic TOPIC [--hold S] [--filter EXPR]
      N times: rclpy.init (a new DDS participant), a node with a default-QoS RobotState
      subscription (content-filtered with --filter), wait for its match and one message (at most
      --hold s), shut down; with --filter every message must pass it (group_present terms only)
  hold --count N [--filter EXPR] [--best-effort] --seconds S
      N RobotState subscriptions (default QoS, content-filtered with --filter) held for S seconds
      without spinning: what a gateway pays for N such readers (make bench's readers suite); the
      node's own cost is not what it measures
TYPE is pkg/msg/Name. Topic names are ROS names (relative ones resolve in the root namespace).
"""
import argparse
import array
import faulthandler
import importlib
import json
import sys
import threading
import time

import rclpy
from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.qos import (DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy,
                       qos_profile_sensor_data)

try:
    from rclpy.subscription_content_filter_options import ContentFilterOptions
except ImportError:  # Jazzy's rclpy (7.1) has no content filter API: rcl's C API, below
    ContentFilterOptions = None


def filter_options(expression, parameters=()):
    """create_subscription's keyword arguments for a content filter, where rclpy has the API (from Kilted's rclpy 9 on: Lyrical's too)."""
    if expression is None or ContentFilterOptions is None:
        return {}
    return {"content_filter_options": ContentFilterOptions(filter_expression=expression,
                                                           expression_parameters=list(parameters))}


def set_rcl_content_filter(subscription, expression, parameters=()):
    """Where rclpy has no content filter API (Jazzy's rclpy 7.1), the one rcl has had since Humble,
    the one rclcpp uses: rcl_subscription_set_content_filter on the subscription's rcl handle, right
    after it was created (before spinning: rmw_fastrtps puts a new, filtered DataReader in place of
    the first, before discovery has matched it). Returns whether rcl reports the filter enabled."""
    import ctypes
    rcl = ctypes.CDLL("librcl.so")  # the wheels' (ros2/env.sh: LD_LIBRARY_PATH)
    for name, argtypes in (("rcl_subscription_content_filter_options_init",
                            [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_void_p]),
                           ("rcl_subscription_set_content_filter", [ctypes.c_void_p, ctypes.c_void_p]),
                           ("rcl_subscription_content_filter_options_fini", [ctypes.c_void_p, ctypes.c_void_p]),
                           ("rcl_subscription_is_cft_enabled", [ctypes.c_void_p])):
        getattr(rcl, name).argtypes = argtypes
    rcl.rcl_subscription_is_cft_enabled.restype = ctypes.c_bool
    handle = subscription.handle.pointer  # the rcl_subscription_t
    # rcl_subscription_content_filter_options_t (a string and an rcutils string array with its
    # allocator: 64 bytes on x86_64), zero-initialized as rcl_get_zero_initialized_... returns it.
    options = ctypes.create_string_buffer(256)
    params = (ctypes.c_char_p * max(1, len(parameters)))(*[p.encode() for p in parameters])
    if rcl.rcl_subscription_content_filter_options_init(handle, expression.encode(), len(parameters), params, options):
        return False
    try:
        if rcl.rcl_subscription_set_content_filter(handle, options):
            return False
    finally:
        rcl.rcl_subscription_content_filter_options_fini(handle, options)
    return bool(rcl.rcl_subscription_is_cft_enabled(handle))


def create_filtered_subscription(node, cls, topic, callback, qos, expression=None, parameters=(), **kwargs):
    """node.create_subscription with a content filter (None: none), by rclpy's API or by rcl's."""
    subscription = node.create_subscription(cls, topic, callback, qos, **kwargs, **filter_options(expression, parameters))
    if expression is not None and ContentFilterOptions is None:
        subscription.rsg_cft_enabled = set_rcl_content_filter(subscription, expression, parameters)
    return subscription


def cft_enabled(subscription):
    if hasattr(subscription, "rsg_cft_enabled"):
        return subscription.rsg_cft_enabled
    return subscription.is_cft_enabled


def message_class(name):
    package, kind, type_name = name.split("/")
    return getattr(importlib.import_module(f"{package}.{kind}"), type_name)


def to_plain(value):
    """A message as JSON-able Python: nested messages as dicts, arrays (numpy, array.array) as lists."""
    if hasattr(value, "get_fields_and_field_types"):
        return {field: to_plain(getattr(value, field)) for field in value.get_fields_and_field_types()}
    if isinstance(value, (list, tuple, array.array)) or type(value).__name__ == "ndarray":
        return [to_plain(item) for item in value]
    if hasattr(value, "item") and not isinstance(value, (int, float, bool, str)):  # numpy scalar
        return value.item()
    return value


def from_plain(cls, values):
    message = cls()
    for field, kind in cls.get_fields_and_field_types().items():
        if field not in values:
            continue
        value = values[field]
        if isinstance(value, dict):
            nested = type(getattr(message, field))
            value = from_plain(nested, value)
        setattr(message, field, value)
    return message


def qos_of(args):
    if args.qos == "sensor_data":
        return qos_profile_sensor_data
    if args.qos == "transient_local":
        return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=args.depth, reliability=ReliabilityPolicy.RELIABLE,
                          durability=DurabilityPolicy.TRANSIENT_LOCAL)
    if args.qos == "keep_all":
        return QoSProfile(history=HistoryPolicy.KEEP_ALL, depth=args.depth, reliability=ReliabilityPolicy.RELIABLE)
    return QoSProfile(depth=args.depth)  # rclpy's default: reliable, volatile, keep last


def say(text):
    print(text, file=sys.stderr, flush=True)


def spin_until(node, predicate, timeout_s):
    deadline = time.monotonic() + timeout_s
    while not predicate():
        if time.monotonic() > deadline:
            return False
        rclpy.spin_once(node, timeout_sec=0.05)
    return True


def subscribe(args):
    cls = message_class(args.type)
    node = rclpy.create_node("rsg_test_sub")
    received = []
    last = [0.0]

    def on_message(message):
        received.append(message)
        last[0] = time.monotonic()
        sys.stdout.write(json.dumps(to_plain(message), separators=(",", ":")) + "\n")
        sys.stdout.flush()

    def on_matched(info):
        say(f"matched {info.current_count}")

    subscription = create_filtered_subscription(node, cls, args.topic, on_message, qos_of(args), args.filter, args.param,
                                                event_callbacks=SubscriptionEventCallbacks(matched=on_matched))
    if args.filter is not None:
        enabled = cft_enabled(subscription)
        say(f"content filter enabled: {enabled}" + ("" if ContentFilterOptions else " (through rcl's C API)"))
        if not enabled:
            say("refused: rmw did not enable the content filter")
            return 3
    deadline = time.monotonic() + args.timeout
    while time.monotonic() < deadline:
        rclpy.spin_once(node, timeout_sec=0.05)
        if args.count and len(received) >= args.count:
            return 0
        if not args.count and received and time.monotonic() - last[0] > args.idle:
            return 0
    say(f"timed out with {len(received)} messages")
    return 0 if not args.count and received else 1


def publish(args):
    cls = message_class(args.type)
    node = rclpy.create_node("rsg_test_pub")
    matched = [0]

    def on_matched(info):
        matched[0] = info.current_count
        say(f"matched {info.current_count}")

    publisher = node.create_publisher(cls, args.topic, QoSProfile(depth=1000),
                                      event_callbacks=PublisherEventCallbacks(matched=on_matched))
    if not spin_until(node, lambda: matched[0] >= args.wait_subscribers, args.timeout):
        say(f"no subscription matched within {args.timeout} s")
        return 1
    with open(args.file) as lines:
        messages = [from_plain(cls, json.loads(line)) for line in lines if line.strip()]
    for message in messages:
        publisher.publish(message)
        if args.period:
            time.sleep(args.period)
    if not publisher.wait_for_all_acked(rclpy.duration.Duration(seconds=args.timeout)):
        say("not every message was acknowledged")
        return 1
    say(f"published {len(messages)}")
    return 0


def graph(args):
    node = rclpy.create_node("rsg_test_graph")
    result = {}

    def infos(topic):
        if args.subscriptions:
            return node.get_subscriptions_info_by_topic(topic)
        return node.get_publishers_info_by_topic(topic)

    spin_until(node, lambda: all(len(infos(topic)) >= args.wait_publishers for topic in args.topics), args.timeout)
    for topic in args.topics:
        result[topic] = []
        for info in infos(topic):
            qos = info.qos_profile
            result[topic].append({
                "node_name": info.node_name, "node_namespace": info.node_namespace, "topic_type": info.topic_type,
                "topic_type_hash": str(info.topic_type_hash), "endpoint_type": info.endpoint_type.name,
                "gid": list(info.endpoint_gid), "reliability": qos.reliability.name, "durability": qos.durability.name,
                "history": qos.history.name, "depth": qos.depth, "deadline_ns": qos.deadline.nanoseconds,
                "liveliness": qos.liveliness.name})
    names = node.get_topic_names_and_types()
    kind = "subscriptions" if args.subscriptions else "publishers"
    print(json.dumps({kind: result, "topics": {name: types for name, types in names}}))
    return 0


def churn(args):
    from rsg_msgs.msg import RobotState  # noqa: the churned nodes read the gateway's state
    wrong = [0]
    for index in range(args.first, args.first + args.count):
        context = rclpy.Context()
        rclpy.init(context=context)
        node = rclpy.create_node(f"rsg_churn_{index}", context=context)
        got = threading.Event()
        matched = [0]

        def on_matched(info, matched=matched):
            matched[0] = info.current_count


        def on_message(message, got=got):
            if args.filter and not all(message.group_present[int(term.split("[")[1].split("]")[0])]
                                       for term in args.filter.split(" AND ")):
                wrong[0] += 1
            got.set()

        create_filtered_subscription(node, RobotState, args.topic, on_message, QoSProfile(depth=10), args.filter or None,
                                     event_callbacks=SubscriptionEventCallbacks(matched=on_matched))
        executor = rclpy.executors.SingleThreadedExecutor(context=context)
        executor.add_node(node)
        deadline = time.monotonic() + args.hold
        while time.monotonic() < deadline and not (matched[0] and got.is_set()):
            executor.spin_once(timeout_sec=0.02)
        say(f"node {index}: matched {matched[0]}, message {got.is_set()}")
        executor.shutdown()
        node.destroy_node()
        rclpy.shutdown(context=context)
    say(f"churned {args.count}, messages failing the filter: {wrong[0]}")
    return 0 if wrong[0] == 0 else 1


def hold(args):
    from rsg_msgs.msg import RobotState  # noqa: the held subscriptions read the gateway's state
    node = rclpy.create_node("rsg_bench_hold")
    qos = qos_profile_sensor_data if args.best_effort else QoSProfile(depth=10)
    subscriptions = [create_filtered_subscription(node, RobotState, args.topic, lambda message: None, qos,
                                                  args.filter or None)
                     for _ in range(args.count)]
    say(f"holding {len(subscriptions)} subscriptions, content filter "
        f"{all(cft_enabled(s) for s in subscriptions) if args.filter else 'none'}")
    time.sleep(args.seconds)
    return 0


def main():
    parser = argparse.ArgumentParser()
    commands = parser.add_subparsers(dest="command", required=True)
    sub = commands.add_parser("sub")
    sub.add_argument("topic")
    sub.add_argument("type")
    sub.add_argument("--qos", default="default", choices=["default", "sensor_data", "transient_local", "keep_all"])
    sub.add_argument("--depth", type=int, default=10)
    sub.add_argument("--count", type=int, default=0)
    sub.add_argument("--timeout", type=float, default=60)
    sub.add_argument("--idle", type=float, default=3)
    sub.add_argument("--filter")
    sub.add_argument("--param", action="append", default=[])
    pub = commands.add_parser("pub")
    pub.add_argument("topic")
    pub.add_argument("type")
    pub.add_argument("--file", required=True)
    pub.add_argument("--wait-subscribers", type=int, default=1)
    pub.add_argument("--period", type=float, default=0.0)
    pub.add_argument("--timeout", type=float, default=60)
    info = commands.add_parser("graph")
    info.add_argument("topics", nargs="+")
    info.add_argument("--wait-publishers", type=int, default=1, help="(or subscriptions)")
    info.add_argument("--subscriptions", action="store_true")
    info.add_argument("--timeout", type=float, default=30)
    ch = commands.add_parser("churn")
    ch.add_argument("--count", type=int, default=50)
    ch.add_argument("--first", type=int, default=0, help="index of the first node (its name's number)")
    ch.add_argument("--topic", default="robot_state")
    ch.add_argument("--hold", type=float, default=5)
    ch.add_argument("--filter")
    ho = commands.add_parser("hold")
    ho.add_argument("--count", type=int, default=1)
    ho.add_argument("--topic", default="/robot_state")
    ho.add_argument("--filter")
    ho.add_argument("--seconds", type=float, default=30)
    ho.add_argument("--best-effort", action="store_true", help="sensor_data QoS instead of the default (reliable)")
    args = parser.parse_args()

    rclpy.init() if args.command != "churn" else None
    try:
        return {"sub": subscribe, "pub": publish, "graph": graph, "churn": churn, "hold": hold}[args.command](args)
    finally:
        if args.command != "churn":
            rclpy.try_shutdown()


if __name__ == "__main__":
    # A crash inside rclpy or its Fast DDS (a peer's, not rsg's) leaves the Python stack on stderr,
    # where the harness shows it, instead of only an exit status.
    faulthandler.enable()
    sys.exit(main())
