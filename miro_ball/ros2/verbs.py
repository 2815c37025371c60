"""What each ``python -m miro_ball.ros2`` command does, in the output shape of ``ros2``'s.

Each verb takes the parsed arguments and a Graph, prints its answer and returns the exit
status; bad input is a CliError (or ValueError) with one line, printed by __main__.
"""
import importlib
import statistics
import sys
import time

from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import GetParameters, ListParameters, SetParameters
from rclpy.node import NodeNameNonExistentError

from miro_ball.common.definitions import prefixes, split_type
from miro_ball.ros2 import convert
from miro_ball.ros2.graph import CliError

PARAMETER_VALUE = {  # ParameterType: (field of ParameterValue, how ros2 param get names it)
    ParameterType.PARAMETER_BOOL: ('bool_value', 'Boolean'),
    ParameterType.PARAMETER_INTEGER: ('integer_value', 'Integer'),
    ParameterType.PARAMETER_DOUBLE: ('double_value', 'Double'),
    ParameterType.PARAMETER_STRING: ('string_value', 'String'),
    ParameterType.PARAMETER_BYTE_ARRAY: ('byte_array_value', 'Byte values'),
    ParameterType.PARAMETER_BOOL_ARRAY: ('bool_array_value', 'Boolean values'),
    ParameterType.PARAMETER_INTEGER_ARRAY: ('integer_array_value', 'Integer values'),
    ParameterType.PARAMETER_DOUBLE_ARRAY: ('double_array_value', 'Double values'),
    ParameterType.PARAMETER_STRING_ARRAY: ('string_array_value', 'String values'),
}


def interface_class(type_name):
    """The class of 'pkg/msg/Name' or 'pkg/srv/Name' ('pkg/Name' is a message); CliError."""
    package, kind, name = split_type(type_name)
    try:
        return getattr(importlib.import_module(f'{package}.{kind}'), name)
    except (ImportError, AttributeError):
        raise CliError(f'no interface {f"{package}/{kind}/{name}"[:200]} is installed (is it '
                       'built? python -m miro_ball.build_interfaces)') from None


def absolute(name):
    """A topic or service name made absolute, checked by ROS's rules: CliError in one
    line for a name ROS refuses (rclpy's own error is a traceback with a caret under it)."""
    from rclpy.exceptions import NameValidationException
    from rclpy.validate_full_topic_name import validate_full_topic_name

    full = name if name.startswith('/') else '/' + name
    try:
        validate_full_topic_name(full)
    except NameValidationException as err:
        reason = str(err).splitlines()[0].split(':', 1)[-1].strip().rstrip(':')
        raise CliError(f'{name[:100]!r} is not a ROS name: {reason}') from None
    return full


def visible(listing, include_hidden):
    """listing ({name: types}) without the names ros2 hides unless asked: those with a part
    that starts with '_', as an action's /name/_action/feedback."""
    from rclpy.topic_or_service_is_hidden import topic_or_service_is_hidden

    return {name: types for name, types in listing.items()
            if include_hidden or not topic_or_service_is_hidden(name)}


def print_listing(listing, show_types):
    """'name' or 'name [type, ...]' a line, sorted: ros2's topic and service lists."""
    for name, types in sorted(listing.items()):
        print(f'{name} [{", ".join(types)}]' if show_types else name)
    return 0


# -- topic ------------------------------------------------------------------------------------
def topic_list(args, graph):
    return print_listing(visible(graph.settle(graph.topics), args.include_hidden_topics),
                         args.show_types)


def topic_info(args, graph):
    topic = absolute(args.topic)
    type_name = graph.topic_type(topic)
    publishers, subscribers = graph.settle(lambda: graph.endpoints(topic))
    print(f'Type: {type_name}')
    for kind, endpoints in (('Publisher', publishers), ('Subscription', subscribers)):
        print(f'{kind} count: {len(endpoints)}')
        if args.verbose:
            print()
            for info in endpoints:
                qos = info.qos_profile
                print(f'Node name: {info.node_name}\nNode namespace: {info.node_namespace}\n'
                      f'Topic type: {info.topic_type}\nEndpoint type: {info.endpoint_type.name}\n'
                      f'QoS profile:\n  Reliability: {qos.reliability.name}\n'
                      f'  History (Depth): {qos.history.name} ({qos.depth})\n'
                      f'  Durability: {qos.durability.name}\n')
    return 0


def topic_echo(args, graph):
    topic = absolute(args.topic)
    msg_class = interface_class(graph.topic_type(topic))
    if args.field:
        convert.field(msg_class(), args.field)  # a field that does not exist: said now
    received = []
    graph.node.create_subscription(msg_class, topic, received.append, graph.qos_for(topic))
    shown = 0
    while True:
        graph.spin(0.05)
        for msg in received:
            value = convert.field(msg, args.field) if args.field else msg
            data = convert.to_data(value, args.truncate_length)
            print(convert.to_yaml(data).rstrip('\n') if isinstance(data, (dict, list))
                  else data, flush=False)
            print('---', flush=True)
            shown += 1
            if args.once:
                return 0
        received.clear()


def topic_hz(args, graph):
    topic = absolute(args.topic)
    msg_class = interface_class(graph.topic_type(topic))
    arrivals = []  # receive times, s: simulated when a /clock runs, else wall

    def heard(msg):
        arrivals.append(now())
        del arrivals[:-args.window - 1]

    sim = '/clock' in graph.topics()
    if sim:
        from rclpy.parameter import Parameter as RclpyParameter
        graph.node.set_parameters([RclpyParameter('use_sim_time', value=True)])

    def now():
        return graph.node.get_clock().now().nanoseconds * 1e-9 if sim else time.monotonic()

    graph.node.create_subscription(msg_class, topic, heard, graph.qos_for(topic))
    while True:
        graph.spin(1.0)
        # Every gap, the zero ones too: a message read before its tick's /clock shares the
        # previous tick's time and the next gap is twice as long; leaving the zeros out made
        # 50 Hz read 47.5.
        gaps = [b - a for a, b in zip(arrivals, arrivals[1:])]
        if not gaps:
            print('no new messages')
            continue
        mean = statistics.fmean(gaps)
        if mean <= 0:
            print('no time has passed between the messages')
            continue
        print(f'average rate: {1.0 / mean:.3f}\n\tmin: {min(gaps):.3f}s max: {max(gaps):.3f}s '
              f'std dev: {statistics.pstdev(gaps):.5f}s window: {len(gaps) + 1}', flush=True)


def topic_pub(args, graph):
    topic = absolute(args.topic)
    msg_class = interface_class(args.type)
    msg = convert.fill(msg_class(), convert.parse_yaml(args.values))
    publisher = graph.node.create_publisher(msg_class, topic, 10)
    times = 1 if args.once else args.times
    if times:  # a few messages: wait until someone listens, or they are lost
        graph.wait(lambda: publisher.get_subscription_count() > 0)
    print('publisher: beginning loop', flush=True)
    count = 0
    while not times or count < times:
        count += 1
        print(f'publishing #{count}: {msg!r}\n', flush=True)
        publisher.publish(msg)
        graph.spin(1.0 / args.rate if not args.once else 0.5)
    return 0


# -- node -------------------------------------------------------------------------------------
def node_list(args, graph):
    print('\n'.join(graph.settle(graph.nodes)))
    return 0


def node_info(args, graph):
    from functools import partial

    from rclpy.action.graph import (get_action_client_names_and_types_by_node,
                                    get_action_server_names_and_types_by_node)

    name, namespace = graph.find_node(args.node)
    node = graph.node
    sections = (('Subscribers', node.get_subscriber_names_and_types_by_node),
                ('Publishers', node.get_publisher_names_and_types_by_node),
                ('Service Servers', node.get_service_names_and_types_by_node),
                ('Service Clients', node.get_client_names_and_types_by_node),
                ('Action Servers', partial(get_action_server_names_and_types_by_node, node)),
                ('Action Clients', partial(get_action_client_names_and_types_by_node, node)))
    try:
        found = graph.settle(lambda: [
            sorted(visible(dict(listing(name, namespace)), args.include_hidden).items())
            for _, listing in sections])
    except NodeNameNonExistentError:
        raise CliError(f'{args.node} left the ROS graph while it was listed') from None
    print(f'{namespace.rstrip("/")}/{name}')
    for (title, _), listing in zip(sections, found):
        print(f'  {title}:')
        # ros2 prints the lines of a section with one print, so an empty one is a blank line
        print('\n'.join(f'    {topic}: {", ".join(types)}' for topic, types in listing))
    return 0


# -- param ------------------------------------------------------------------------------------
def _parameter_service(graph, node, service):
    name, namespace = graph.find_node(node)
    return f'{namespace.rstrip("/")}/{name}/{service}'


def _parameter_names(graph, node):
    service = _parameter_service(graph, node, 'list_parameters')
    return graph.call(service, ListParameters, ListParameters.Request()).result.names


def _unknown(graph, node, name):
    """Why node has no parameter name, with the nearest names (rclpy would say 'Invalid
    access to undeclared parameter(s): []'); None if it has."""
    import difflib

    known = _parameter_names(graph, node)
    if name in known:
        return None
    near = difflib.get_close_matches(name, known, n=3)
    hint = ('; did you mean ' + ' or '.join(map(repr, near)) + '?' if near else
            f' (the parameters: python -m miro_ball.ros2 param list {node})')
    return f'no parameter {name!r} on {node}{hint}'


def param_list(args, graph):
    for name in sorted(_parameter_names(graph, args.node)):
        print(f'  {name}')
    return 0


def param_get(args, graph):
    service = _parameter_service(graph, args.node, 'get_parameters')
    values = graph.call(service, GetParameters, GetParameters.Request(names=[args.name])).values
    if not values or values[0].type not in PARAMETER_VALUE:
        if (why := _unknown(graph, args.node, args.name)) is not None:
            raise CliError(why)
        print('Parameter not set.')
        return 1
    field, word = PARAMETER_VALUE[values[0].type]
    value = getattr(values[0], field)
    print(f'{word} value is: {list(value) if word.endswith("values") else value}')
    return 0


def parameter_value(text):
    """A ParameterValue from the command line's text, typed as YAML reads it (ros2's rule)."""
    import yaml

    try:
        value = text if convert.has_alias(text) else yaml.safe_load(text)
    except (yaml.YAMLError, RecursionError):
        value = text
    kinds = ((bool, ParameterType.PARAMETER_BOOL), (int, ParameterType.PARAMETER_INTEGER),
             (float, ParameterType.PARAMETER_DOUBLE), (str, ParameterType.PARAMETER_STRING))
    if isinstance(value, int) and not isinstance(value, bool) and \
            not -2 ** 63 <= value < 2 ** 63:  # was a traceback from inside rclpy
        raise CliError(f'{text[:100]!r} is beyond an integer parameter (64 bits: '
                       f'{-2 ** 63} to {2 ** 63 - 1})')
    for kind, code in kinds:
        if isinstance(value, kind):
            field = PARAMETER_VALUE[code][0]
            return ParameterValue(type=code, **{field: value})
    raise CliError(f'{text!r} is not a parameter value (a bool, integer, number or string)')


def param_set(args, graph):
    service = _parameter_service(graph, args.node, 'set_parameters')
    request = SetParameters.Request(parameters=[Parameter(name=args.name,
                                                          value=parameter_value(args.value))])
    result = graph.call(service, SetParameters, request).results[0]
    # As ros2 param set says it: a refusal on stderr, and exit status 0 all the same (the
    # request went through; the node said no)
    reason = result.reason if result.successful else \
        _unknown(graph, args.node, args.name) or result.reason
    said = 'Set parameter successful' if result.successful else 'Setting parameter failed'
    print(said + (f': {reason}' if reason else ''),
          file=sys.stdout if result.successful else sys.stderr)
    return 0


# -- service, interface -----------------------------------------------------------------------
def service_list(args, graph):
    return print_listing(visible(graph.settle(graph.services), args.include_hidden_services),
                         args.show_types)


def service_call(args, graph):
    service = absolute(args.service)
    srv_class = interface_class(args.type)
    if not hasattr(srv_class, 'Request'):
        raise CliError(f'{args.type} is not a service type (package/srv/Name)')
    request = convert.fill(srv_class.Request(), convert.parse_yaml(args.values))
    response = graph.call(service, srv_class, request, say=lambda: print(
        f'requester: making request: {request!r}\n', flush=True))
    print(f'response:\n{response!r}\n')
    return 0


def installed_interfaces():
    """{'msg': [...], 'srv': [...], 'action': [...]} of 'pkg/kind/Name' of every package
    installed (the ament index's rosidl_interfaces, each package from the first prefix
    that has it), sorted."""
    found = {}
    for prefix in reversed(prefixes()):  # the first prefix wins: read it last
        index = prefix / 'share' / 'ament_index' / 'resource_index' / 'rosidl_interfaces'
        for resource in sorted(index.glob('*')) if index.is_dir() else []:
            if resource.is_file():
                found[resource.name] = resource.read_text(errors='replace').split()
    kinds = {'msg': set(), 'srv': set(), 'action': set()}
    for package, entries in found.items():
        for entry in entries:  # 'msg/Bounds.idl', 'msg/Bounds.msg', ...
            kind, _, file_name = entry.split(';')[0].partition('/')
            if kind in kinds and file_name:
                kinds[kind].add(f'{package}/{kind}/{file_name.rsplit(".", 1)[0]}')
    return {kind: sorted(names) for kind, names in kinds.items()}


def interface_list(args, graph=None):
    kinds = installed_interfaces()
    chosen = [kind for kind, only in (('msg', args.only_msgs), ('srv', args.only_srvs),
                                      ('action', args.only_actions)) if only] or list(kinds)
    for kind in chosen:
        print({'msg': 'Messages:', 'srv': 'Services:', 'action': 'Actions:'}[kind])
        for name in kinds[kind]:
            print(f'    {name}')
    return 0


def interface_show(args, graph=None):
    from miro_ball.ros2.interface_text import shown

    try:
        print('\n'.join(shown(args.type, comments=not args.no_comments,
                               nested_comments=args.all_comments)))
    except ValueError as err:
        raise CliError(str(err)) from None
    except ImportError as err:  # rosidl's parser: a full ROS 2 has it, pip's msgs extra too
        raise CliError(f'interface show needs {err.name} (pip install \'miro_ball[msgs]\')') \
            from None
    return 0
