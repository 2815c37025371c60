"""The ``action`` verbs of ``python -m miro_ball.ros2`` (list, info, send_goal), in the output
shape of ``ros2 action``'s, on rclpy's own action client and graph queries.

send_goal prints what ros2's does, line for line, quirks kept (a message's YAML starts on the
title's next line indented and its other lines are not), so what reads ros2's output reads
ours; it exits 0 once the server has answered, whatever the goal's status (as ros2 does).
"""
import time
import uuid

from action_msgs.msg import GoalStatus
from rclpy.action import ActionClient
from rclpy.action.graph import (get_action_client_names_and_types_by_node,
                                get_action_names_and_types,
                                get_action_server_names_and_types_by_node)
from rclpy.node import NodeNameNonExistentError
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from unique_identifier_msgs.msg import UUID

from miro_ball.ros2 import convert
from miro_ball.ros2.graph import CliError
from miro_ball.ros2.verbs import absolute, interface_class, print_listing

STATUS = {GoalStatus.STATUS_ACCEPTED: 'ACCEPTED', GoalStatus.STATUS_EXECUTING: 'EXECUTING',
          GoalStatus.STATUS_CANCELING: 'CANCELING', GoalStatus.STATUS_SUCCEEDED: 'SUCCEEDED',
          GoalStatus.STATUS_CANCELED: 'CANCELED', GoalStatus.STATUS_ABORTED: 'ABORTED'}
FEEDBACK_QUIET_S = 0.1  # wall seconds of no feedback after which -f takes it all printed


def action_class(type_name):
    """The class of 'pkg/action/Name'; CliError if it is not an installed action."""
    cls = interface_class(type_name)
    if not hasattr(cls, 'Goal'):
        raise CliError(f'{type_name} is not an action type (package/action/Name, as '
                       'simulation_interfaces/action/SimulateSteps)')
    return cls


def _yaml(msg):
    """A message as ros2 action send_goal prints it: YAML, every array whole."""
    return convert.to_yaml(convert.to_data(msg, truncate=0))


def action_list(args, graph):
    listing = graph.settle(lambda: dict(get_action_names_and_types(graph.node)))
    if args.count_actions:
        print(len(listing))
        return 0
    return print_listing(listing, args.show_types)


def _ends(graph, action):
    """([(client node, [types])], [(server node, [types])]) of one action, sorted."""
    found = ([], [])
    for name, namespace in graph.node.get_node_names_and_namespaces():
        full = f'{namespace.rstrip("/")}/{name}'
        for ends, listing in zip(found, (get_action_client_names_and_types_by_node,
                                         get_action_server_names_and_types_by_node)):
            try:
                types = dict(listing(graph.node, name, namespace)).get(action)
            except NodeNameNonExistentError:  # it has just gone
                continue
            if types:
                ends.append((full, list(types)))
    return tuple(sorted(ends) for ends in found)


def action_info(args, graph):
    action = absolute(args.action)
    clients, servers = graph.settle(lambda: _ends(graph, action))
    print(f'Action: {action}')
    for title, ends in (('Action clients', clients), ('Action servers', servers)):
        print(f'{title}: {len(ends)}')
        for node, types in [] if args.count else ends:
            print(f'    {node} [{", ".join(types)}]' if args.show_types else f'    {node}')
    return 0


class FeedbackPrinter:
    """Prints each feedback of one goal, from a subscription of its own to the action's
    feedback topic: rclpy's client forgets a goal's feedback once its result is in, and
    the result can overtake the feedback still queued (the simulator steps and sends
    hundreds at once; 784 of 1000 were printed). Every message is kept until printed."""

    def __init__(self, graph, cls, action, goal_id):
        self.goal_id = goal_id
        self.last = time.monotonic()
        self.subscription = graph.node.create_subscription(
            cls.Impl.FeedbackMessage, f'{action}/_action/feedback', self._heard,
            QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE))

    def ready(self):
        """Whether the server's feedback publisher is matched: the first feedback of a
        goal sent before then was lost."""
        return self.subscription.get_publisher_count() > 0

    def _heard(self, message):
        if bytes(message.goal_id.uuid) == self.goal_id:
            print(f'Feedback:\n    {_yaml(message.feedback)}', flush=True)
            self.last = time.monotonic()

    def drain(self, graph):
        """Print the feedback still queued or on its way once the result is in."""
        while time.monotonic() - self.last < FEEDBACK_QUIET_S:
            graph.spin(0.01)


def action_send_goal(args, graph):
    action = absolute(args.action)
    cls = action_class(args.type)
    goal = convert.fill(cls.Goal(), convert.parse_yaml(args.goal))
    client = ActionClient(graph.node, cls, action)
    goal_id = uuid.uuid4().bytes  # chosen here, to know the goal's feedback from others'
    feedback = FeedbackPrinter(graph, cls, action, goal_id) if args.feedback else None
    print('Waiting for an action server to become available...', flush=True)
    if not graph.wait(lambda: client.server_is_ready() and (not feedback or feedback.ready())):
        raise CliError(f'no action server {action} on ROS domain {graph.domain} (the '
                       'actions: python -m miro_ball.ros2 action list)')
    print(f'Sending goal:\n     {_yaml(goal)}', flush=True)
    sent = client.send_goal_async(goal, goal_uuid=UUID(uuid=list(goal_id)))
    if not graph.wait(sent.done):
        raise CliError(f'{action} did not answer the goal')
    handle = sent.result()
    if not handle.accepted:
        print('Goal was rejected.')
        return 0
    print(f'Goal accepted with ID: {bytes(handle.goal_id.uuid).hex()}\n', flush=True)
    result = handle.get_result_async()
    try:
        while not result.done():  # as long as the goal runs: a goal may take minutes
            graph.spin(0.05)
    except KeyboardInterrupt:
        _cancel(graph, action, handle, result)
    if feedback:
        feedback.drain(graph)
    answer = result.result()
    print(f'Result:\n    {_yaml(answer.result)}')
    print(f'Goal finished with status: {STATUS.get(answer.status, "UNKNOWN")}')
    return 0


def _cancel(graph, action, handle, result):
    """Ask the server to cancel the goal (Ctrl+C) and wait for its result; a second Ctrl+C
    leaves at once. A goal that ended meanwhile keeps its own status."""
    print('Canceling goal...', flush=True)
    canceling = handle.cancel_goal_async()
    if not graph.wait(canceling.done):
        raise CliError(f'{action} did not answer the cancel request')
    if canceling.result().goals_canceling:
        print('Goal canceled.', flush=True)
    if not graph.wait(result.done):
        raise CliError(f'{action} accepted the cancel but sent no result')
