"""python -m miro_ball.ros2 VERB ...: the ``ros2`` command line's everyday verbs for an install
with no ROS 2 of its own (the ROS wheels from PyPI), with ros2's arguments and output:

    python -m miro_ball.ros2 topic list -t
    python -m miro_ball.ros2 topic echo /miro/sensors/battery --once
    python -m miro_ball.ros2 topic pub /miro/control/cmd_vel geometry_msgs/msg/TwistStamped \\
        '{twist: {linear: {x: 0.2}}}' -r 10
    python -m miro_ball.ros2 interface show miro2_msg/msg/SensorsPackage
    python -m miro_ball.ros2 param get /miro_sim camera_rate
    python -m miro_ball.ros2 service call /miro_sim/set_simulation_state \\
        simulation_interfaces/srv/SetSimulationState '{state: {state: 2}}'
    python -m miro_ball.ros2 action send_goal /miro_sim/simulate_steps \\
        simulation_interfaces/action/SimulateSteps '{steps: 100}' -f

It sees the ROS domain of the shell it runs in (ROS_DOMAIN_ID), as ros2 does. Without
ros2's daemon, a listing listens until the graph is complete (3.5 s or more; if it is still
changing at 10 s, the answer comes with a line on stderr that it may be incomplete).
"""
import argparse
import math
import os
import sys

from rclpy.executors import ExternalShutdownException

from miro_ball.ros2 import actions, verbs
from miro_ball.ros2.convert import TRUNCATE
from miro_ball.ros2.graph import CliError, Graph

PROG = 'python -m miro_ball.ros2'


def positive_rate(text):
    value = float(text)
    if not (math.isfinite(value) and 0 < value <= 1000):
        raise argparse.ArgumentTypeError(f'{text} is not a rate between 0 and 1000 Hz')
    return value


def build_parser():
    parser = argparse.ArgumentParser(prog=PROG, description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    commands = parser.add_subparsers(dest='command', metavar='COMMAND', required=True)

    def group(name, about):
        sub = commands.add_parser(name, help=about, description=about)
        return sub.add_subparsers(dest='verb', metavar='VERB', required=True)

    def verb(parent, name, about, run, needs_graph=True, own_ctrl_c=False):
        sub = parent.add_parser(name, help=about, description=about)
        sub.set_defaults(run=run, needs_graph=needs_graph, own_ctrl_c=own_ctrl_c)
        return sub

    topic = group('topic', 'topics: list, echo, hz, info, pub')
    v = verb(topic, 'list', 'the topics of the graph', verbs.topic_list)
    v.add_argument('-t', '--show-types', action='store_true', help='with their types')
    v.add_argument('--include-hidden-topics', action='store_true',
                   help="those of a name part that starts with '_' too (an action's)")
    v = verb(topic, 'echo', "print a topic's messages as YAML", verbs.topic_echo)
    v.add_argument('topic')
    v.add_argument('--once', action='store_true', help='one message, then exit')
    v.add_argument('--field', help="only this field (dotted: 'twist.linear.x')")
    v.add_argument('--truncate-length', type=int, default=TRUNCATE,
                   help=f'arrays show this many items, then ... ({TRUNCATE}; 0: all)')
    v = verb(topic, 'hz', "a topic's rate (of simulated time when a /clock runs)",
             verbs.topic_hz)
    v.add_argument('topic')
    v.add_argument('--window', type=int, default=100, help='messages averaged over (100)')
    v = verb(topic, 'info', "a topic's type and how many publish and subscribe",
             verbs.topic_info)
    v.add_argument('topic')
    v.add_argument('-v', '--verbose', action='store_true', help='each endpoint and its QoS')
    v = verb(topic, 'pub', 'publish a message given as YAML', verbs.topic_pub)
    v.add_argument('topic')
    v.add_argument('type', help='the message type, as geometry_msgs/msg/TwistStamped')
    v.add_argument('values', nargs='?', default='{}', help="the fields, as '{x: 1.0}'")
    how = v.add_mutually_exclusive_group()
    how.add_argument('-1', '--once', action='store_true', help='publish one message, then exit')
    how.add_argument('-r', '--rate', type=positive_rate, default=1.0,
                     help='messages per second (1)')
    v.add_argument('-t', '--times', type=int, default=0,
                   help='publish this many messages, then exit (0: until Ctrl+C)')

    node = group('node', 'nodes: list, info')
    verb(node, 'list', 'the nodes of the graph', verbs.node_list)
    v = verb(node, 'info', "a node's publishers, subscribers and services", verbs.node_info)
    v.add_argument('node', help='its full name, as /miro_sim')
    v.add_argument('--include-hidden', action='store_true',
                   help="topics and services of a name part that starts with '_' too")

    interface = group('interface', 'message, service and action types: list, show')
    v = verb(interface, 'list', 'the installed types', verbs.interface_list, needs_graph=False)
    v.add_argument('-m', '--only-msgs', action='store_true', help='the message types only')
    v.add_argument('-s', '--only-srvs', action='store_true', help='the service types only')
    v.add_argument('-a', '--only-actions', action='store_true', help='the action types only')
    v = verb(interface, 'show', "a type's fields", verbs.interface_show, needs_graph=False)
    v.add_argument('type', help='as miro2_msg/msg/SensorsPackage, std_srvs/srv/Trigger or '
                   'simulation_interfaces/action/SimulateSteps')
    comments = v.add_mutually_exclusive_group()
    comments.add_argument('--all-comments', action='store_true',
                          help='the comments of the types it holds too')
    comments.add_argument('--no-comments', action='store_true',
                          help='no comments, and no blank lines')

    param = group('param', "a node's parameters: list, get, set")
    v = verb(param, 'list', "a node's parameter names", verbs.param_list)
    v.add_argument('node')
    v = verb(param, 'get', "a parameter's value", verbs.param_get)
    v.add_argument('node')
    v.add_argument('name')
    v = verb(param, 'set', 'change a parameter while the node runs', verbs.param_set)
    v.add_argument('node')
    v.add_argument('name')
    v.add_argument('value', help='read as YAML: 2, 2.5, true, text')

    service = group('service', 'services: list, call')
    v = verb(service, 'list', 'the services of the graph', verbs.service_list)
    v.add_argument('-t', '--show-types', action='store_true', help='with their types')
    v.add_argument('--include-hidden-services', action='store_true',
                   help="those of a name part that starts with '_' too (an action's)")
    v = verb(service, 'call', 'call a service with a request given as YAML', verbs.service_call)
    v.add_argument('service')
    v.add_argument('type', help='as std_srvs/srv/Trigger')
    v.add_argument('values', nargs='?', default='{}', help="the request's fields as YAML")

    action = group('action', 'actions: list, info, send_goal')
    v = verb(action, 'list', 'the actions of the graph', actions.action_list)
    v.add_argument('-t', '--show-types', action='store_true', help='with their types')
    v.add_argument('-c', '--count-actions', action='store_true', help='only how many')
    v = verb(action, 'info', "an action's clients and servers", actions.action_info)
    v.add_argument('action', help='as /miro_sim/simulate_steps')
    v.add_argument('-t', '--show-types', action='store_true', help='with their types')
    v.add_argument('-c', '--count', action='store_true', help='only how many')
    v = verb(action, 'send_goal', 'send a goal given as YAML and wait for its result '
             '(Ctrl+C cancels it)', actions.action_send_goal, own_ctrl_c=True)
    v.add_argument('action', help='as /miro_sim/simulate_steps')
    v.add_argument('type', help='as simulation_interfaces/action/SimulateSteps')
    v.add_argument('goal', nargs='?', default='{}', help="the goal's fields as YAML")
    v.add_argument('-f', '--feedback', action='store_true', help='print each feedback')
    return parser


def main(argv=None):
    parser = build_parser()
    args = parser.parse_args(argv)
    if getattr(args, 'times', 0) < 0 or getattr(args, 'window', 1) < 1 \
            or getattr(args, 'truncate_length', 0) < 0:
        parser.error('--times, --window and --truncate-length take a positive count')
    graph = None
    try:
        if args.needs_graph:
            graph = Graph(own_ctrl_c=args.own_ctrl_c)
        return args.run(args, graph)
    except (CliError, ValueError) as err:
        print(f'{PROG}: {err}', file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 0
    except BrokenPipeError:  # `| head` has read what it wanted
        sys.stdout = open(os.devnull, 'w')
        return 0
    except ExternalShutdownException:  # Ctrl+C while it waits in rclpy
        return 0
    finally:
        if graph is not None:
            graph.close()


if __name__ == '__main__':
    sys.exit(main())
