"""Launch files as python -m miro_ball.launch reads them, without starting anything: the
subset of ROS 2's XML and YAML formats (each element, substitutions, include, group
namespaces), what is refused in one line, the command lines built, what happens when a
process ends, and the bundled files (installed where ros2 launch looks for them)."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

from miro_ball.launch import LaunchError
from miro_ball.launch.executables import command, console_scripts
from miro_ball.launch.exits import after_exit, GoOn, Restart, Stop
from miro_ball.launch.files import bundled, find, share_folder
from miro_ball.launch.plan import Process, make_plan

ROOT = Path(__file__).resolve().parents[1]
SCRIPTS = {'talker': 'demo.talk:main', 'listener': 'demo.listen:main'}

XML = '''<launch>
  <arg name="robot" default="miro01" description="who"/>
  <arg name="rate" default="$(var robot)_x"/>
  <let name="port" value="80$(env TEST_PORT 80)"/>
  <node pkg="demo" exec="talker" name="talk" namespace="$(var robot)" output="screen"
        args="--port $(var port) 'two words'" respawn="true" respawn_delay="1.5">
    <param name="rate" value="$(var rate)"/>
    <remap from="out" to="/chatter"/>
  </node>
  <group>
    <push_ros_namespace namespace="team"/>
    <let name="robot" value="inner"/>
    <node pkg="demo" exec="listener"/>
    <node pkg="demo" exec="listener" namespace="$(var robot)"/>
    <node pkg="demo" exec="listener" namespace="/top" if="false"/>
  </group>
  <executable cmd="echo $(var robot)" name="say" unless="true"/>
  <executable cmd="echo $(var robot)" on_exit="shutdown"/>
  <include file="child.launch.xml">
    <arg name="who" value="$(var robot)"/>
  </include>
</launch>
'''
YAML = '''launch:
- arg: {name: robot, default: miro01, description: who}
- arg: {name: rate, default: $(var robot)_x}
- let: {name: port, value: 80$(env TEST_PORT 80)}
- node:
    pkg: demo
    exec: talker
    name: talk
    namespace: $(var robot)
    output: screen
    args: --port $(var port) 'two words'
    respawn: true
    respawn_delay: 1.5
    param: [{name: rate, value: $(var rate)}]
    remap: [{from: out, to: /chatter}]
- group:
  - push_ros_namespace: {namespace: team}
  - let: {name: robot, value: inner}
  - node: {pkg: demo, exec: listener}
  - node: {pkg: demo, exec: listener, namespace: $(var robot)}
  - node: {pkg: demo, exec: listener, namespace: /top, if: false}
- executable: {cmd: echo $(var robot), name: say, unless: true}
- executable: {cmd: echo $(var robot), on_exit: shutdown}
- include:
    file: child.launch.xml
    arg: [{name: who, value: $(var robot)}]
'''
CHILD = '''<launch>
  <arg name="who"/>
  <node pkg="demo" exec="listener" name="heard_$(var who)"/>
</launch>
'''


def write(folder, name, text):
    path = folder / name
    path.write_text(text)
    return path


def plan(path, **given):
    return make_plan(path, given, share=lambda pkg: Path('/share') / pkg, environ={})


def refusal(tmp_path, text, suffix='.launch.xml', **given):
    """The one-line message a launch file (or argument) is refused with."""
    with pytest.raises(LaunchError) as caught:
        plan(write(tmp_path, 'bad' + suffix, text), **given)
    message = str(caught.value)
    assert '\n' not in message
    return message


@pytest.fixture(params=['xml', 'yaml'])
def sample(request, tmp_path):
    write(tmp_path, 'child.launch.xml', CHILD)
    return write(tmp_path, f'sample.launch.{request.param}', XML if request.param == 'xml'
                 else YAML)


def test_each_element_means_in_xml_and_yaml_what_ros2_launch_makes_of_it(sample):
    processes = plan(sample).processes
    assert [p.label for p in processes] == ['miro01/talk', 'team/listener', 'team/inner/listener',
                                            'echo', 'heard_miro01']
    talk = processes[0]
    assert (talk.pkg, talk.exec, talk.name, talk.namespace) == ('demo', 'talker', 'talk',
                                                                 '/miro01')
    assert talk.args == ('--port', '8080', 'two words')
    assert talk.params == (('rate', 'miro01_x'),) and talk.remaps == (('out', '/chatter'),)
    assert talk.respawn and talk.respawn_delay == 1.5
    assert [p.namespace for p in processes[1:3]] == ['/team', '/team/inner']
    # The group's let stays in the group; an include gets what it is given.
    assert processes[3].cmd == ('echo', 'miro01') and not processes[3].respawn
    assert [p.shutdown_on_exit for p in processes] == [False, False, False, True, False]
    assert processes[4].name == 'heard_miro01' and processes[4].namespace is None


def test_arguments_given_win_over_defaults_and_reach_the_files_included(sample):
    processes = plan(sample, robot='miro02').processes
    assert processes[0].namespace == '/miro02' and processes[0].params == (('rate', 'miro02_x'),)
    assert processes[-1].name == 'heard_miro02'
    args = plan(sample).args
    assert list(args) == ['robot', 'rate']  # 'who' is the including file's to set
    assert args['robot'].description == 'who' and args['robot'].default == 'miro01'


def test_substitutions(tmp_path):
    text = ('<launch><arg name="a" default="x"/><executable cmd="echo $(var a) '
            '$(find-pkg-share miro_ball)/launch $(env HOME) $(env NOPE \'no pe\')"/></launch>')
    path = write(tmp_path, 'subst.launch.xml', text)
    found = make_plan(path, {}, share=lambda pkg: Path('/s') / pkg, environ={'HOME': '/h'})
    # The default is one word of $(env ...); the command is split after substitution.
    assert found.processes[0].cmd == ('echo', 'x', '/s/miro_ball/launch', '/h', 'no', 'pe')


def test_an_argument_without_default_is_required(tmp_path):
    path = write(tmp_path, 'req.launch.xml', CHILD)
    assert plan(path).missing == ['who'] and plan(path, who='a').missing == []


def test_a_process_that_ends_ends_the_run_is_restarted_or_leaves_the_others_as_its_file_says():
    node = Process('miro01/kick_blue_ball', Path('x'), shutdown_on_exit=True)
    assert after_exit(node, 3, now=10.0) == Stop('miro01/kick_blue_ball exited with code 3; '
                                                 'stopping the others')
    assert after_exit(node, -9, 10.0).line.startswith('miro01/kick_blue_ball was killed by '
                                                       'SIGKILL;')
    again = after_exit(Process('a', Path('x'), respawn=True, respawn_delay=2.0), 0, now=10.0)
    assert again == Restart(12.0, 'a exited with code 0; respawning in 2 s')
    # As in ROS 2's launch: shutdown wins over respawn; with neither, the others go on.
    both = Process('a', Path('x'), respawn=True, shutdown_on_exit=True)
    assert isinstance(after_exit(both, 0, 10.0), Stop)
    assert after_exit(Process('a', Path('x')), 1, 10.0) == GoOn(
        'a exited with code 1; the others go on (its file does not say on_exit="shutdown")')
    assert after_exit(Process('a', Path('x')), 0, 10.0, others=False) == GoOn(
        'a exited with code 0')


def test_the_command_line_of_a_node_and_of_an_executable(sample):
    talk, listener, _, echo, _ = plan(sample).processes
    line = command(talk, scripts=lambda pkg: SCRIPTS, python='py')
    assert line[:2] == ['py', '-c'] and 'from demo.talk import main' in line[2]
    assert line[3:] == ['--port', '8080', 'two words', '--ros-args', '-r', '__node:=talk',
                        '-r', '__ns:=/miro01', '-r', 'out:=/chatter', '-p', 'rate:=miro01_x']
    assert command(listener, lambda pkg: SCRIPTS, 'py')[3:] == ['--ros-args', '-r',
                                                                '__ns:=/team']
    assert command(echo, lambda pkg: SCRIPTS, 'py') == ['echo', 'miro01']


def test_the_command_line_runs_the_console_script_as_its_own_would(tmp_path):
    node = Process('kick', tmp_path, pkg='miro_ball', exec='kick_blue_ball', args=('--help',))
    output = subprocess.run(command(node), capture_output=True, text=True, check=True).stdout
    assert output.startswith('usage: kick_blue_ball ')


@pytest.mark.parametrize('text, words', [
    ('<launch><set_env name="a" value="b"/></launch>', '<set_env> is not supported'),
    ('<launch><node pkg="a" exec="b" launch-prefix="gdb"/></launch>',
     "attribute 'launch-prefix' is not supported"),
    ('<launch><group><param name="a" value="b"/></group></launch>',
     '<param> inside <group> is not supported'),
    ('<launch><node pkg="a"/></launch>', "<node> needs the attribute 'exec'"),
    ('<launch><executable cmd="$(command ls)"/></launch>', '$(command ls) is not supported'),
    ('<launch><executable cmd="$(var $(var a))"/></launch>', 'inside another'),
    ('<launch><executable cmd="$(var nobody)"/></launch>', "no arg or let named 'nobody'"),
    ('<launch><executable cmd="$(env NOT_SET_HERE)"/></launch>', 'has no NOT_SET_HERE'),
    ('<launch><executable cmd="a" if="maybe"/></launch>', "true or false (or 1, 0), got 'maybe'"),
    ('<launch><executable cmd="a" respawn_delay="-1"/></launch>', 'respawn_delay'),
    ('<launch><node pkg="a" exec="b" on_exit="restart"/></launch>',
     '<node>: on_exit=\'restart\': the only value is "shutdown"'),
    ('<launch><node pkg="a" exec="b" args="\'open"/></launch>', 'quotation'),
    ('<launch><include file="child.launch.py"/></launch>', 'Python launch files need ros2'),
    ('<launch><include file="bad.launch.xml"/></launch>', 'include itself'),
    ('<launch><node>', 'not well-formed XML'),
    # Bounds in all, whatever the depth: actions, processes, a value that doubles itself.
    ('<launch>' + '<let name="a" value="b"/>' * 5001 + '</launch>', 'over 5000 actions in all'),
    ('<launch>' + '<executable cmd="a"/>' * 101 + '</launch>', 'over 100 processes in all'),
    ('<launch><let name="a" value="ab"/>' + '<let name="a" value="$(var a)$(var a)"/>' * 20
     + '</launch>', 'over 10000 characters once substituted'),
    ('<robot/>', 'the root element is <robot>'),
])
def test_what_is_outside_the_subset_is_refused_in_one_line_naming_it_and_its_file(
        tmp_path, text, words):
    message = refusal(tmp_path, text)
    assert words in message and 'bad.launch.xml' in message, message


@pytest.mark.parametrize('text, words', [
    ('launch:\n- node: {pkg: a, exec: b, env: {A: 1}}\n', "attribute 'env' is not supported"),
    ('launch:\n- node: {pkg: a, exec: b}\n  let: {name: a, value: b}\n', 'mapping of one key'),
    ('nodes: []\n', 'launch: [actions]'),
    ('launch: [\n', 'not valid YAML'),
    ('launch:\n- timer: {period: 1}\n', '<timer> is not supported'),
    ('launch:\n- node: {pkg: a, exec: b, param: {name: a}}\n', 'param holds a list'),
    ('launch:\n- node: {pkg: a, exec: b, name: [1, 2]}\n', 'must be a single value'),
    # Aliases are refused before they are expanded: these 300 bytes are 10^7 values.
    ('launch:\n- - &a [x, x, x, x, x, x, x, x, x, x]\n'
     + ''.join(f'  - &{b} [{", ".join([f"*{a}"] * 10)}]\n' for a, b in zip('abcdef', 'bcdefg')),
     'YAML aliases (*name)'),
])
def test_yaml_outside_the_subset_is_refused_too(tmp_path, text, words):
    message = refusal(tmp_path, text, suffix='.launch.yaml')
    assert words in message and 'bad.launch.yaml' in message, message


def self_including(folder, depth=19, fan_out=4):
    """A launch file that includes itself fan_out times, each include's arguments shifted
    so that the includes stop at ``depth``, under the depth limit: fan_out^depth includes."""
    names = [f'a{i}' for i in range(depth)]
    declared = ''.join(f'<arg name="{name}" default="true"/>' for name in names)
    shifted = ''.join(f'<arg name="{name}" value="$(var {after})"/>'
                      for name, after in zip(names, names[1:]))
    include = (f'<include file="bomb.launch.xml" if="$(var a0)">{shifted}'
               f'<arg name="{names[-1]}" value="false"/></include>')
    return write(folder, 'bomb.launch.xml', f'<launch>{declared}{include * fan_out}'
                                            '<executable cmd="true"/></launch>')


def test_a_file_including_itself_under_the_depth_limit_is_refused_at_once(tmp_path):
    bomb = self_including(tmp_path)
    assert len(bomb.read_bytes()) < 4000  # 4^19 includes, each within the depth limit
    refused = run_cli(str(bomb), '--print')
    assert refused.returncode == 2 and refused.stdout == '', refused.stderr
    assert len(refused.stderr.splitlines()) == 1, refused.stderr
    assert 'bomb.launch.xml: <include>: over 100 includes in all' in refused.stderr
    # Two deep it is an ordinary file: the bound is on the total, not on what is usual.
    assert [p.cmd for p in plan(self_including(tmp_path, depth=2)).processes] == \
        [('true',)] * (1 + 4 + 16)


@pytest.mark.parametrize('name, text, words', [
    ('deep.launch.xml', '<launch>' + '<group>' * 5000 + '</group>' * 5000 + '</launch>',
     '<group> is nested over 12 elements deep'),
    ('deep.launch.yaml', 'launch: ' + '[{group: ' * 5000 + '[]' + '}]' * 5000,
     'nested too deeply'),
    ('deep.launch.yaml', 'launch: ' + '[{group: ' * 20 + '[]' + '}]' * 20,
     '<group> is nested over 12 elements deep'),
])
def test_a_file_nested_too_deep_gets_one_line(tmp_path, name, text, words):
    refused = run_cli(str(write(tmp_path, name, text)), '--print')
    assert refused.returncode == 2 and refused.stdout == '', refused.stderr[-2000:]
    assert len(refused.stderr.splitlines()) == 1 and words in refused.stderr, refused.stderr


def test_an_include_of_a_fifo_or_a_folder_is_refused_without_waiting(tmp_path):
    os.mkfifo(tmp_path / 'fifo.launch.xml')
    (tmp_path / 'folder.launch.xml').mkdir()
    for name in ('fifo.launch.xml', 'folder.launch.xml'):
        including = write(tmp_path, 'main.launch.xml', f'<launch><include file="{name}"/>'
                                                       '</launch>')
        refused = run_cli(str(including), '--print')  # a hang would be the guard's timeout
        assert refused.returncode == 2 and len(refused.stderr.splitlines()) == 1
        assert f"main.launch.xml: <include>: {tmp_path / name}: can not be read ('{name}' " \
            'is not a regular file)' in refused.stderr, refused.stderr


def test_a_file_too_big_is_refused(tmp_path):
    big = write(tmp_path, 'big.launch.xml', '<launch>' + ' ' * (1 << 20) + '</launch>')
    assert refusal(tmp_path, f'<launch><include file="{big}"/></launch>').endswith(
        'big.launch.xml: over 1 MB, too big for a launch file')


# A Ctrl+C (SIGINT to itself) as the launcher imports its planner, or as it plans.
INTERRUPTED = {
    'import': """
class Interrupt:
    def find_spec(self, name, path=None, target=None):
        if name == 'miro_ball.launch.plan':
            os.kill(os.getpid(), signal.SIGINT)
sys.meta_path.insert(0, Interrupt())
""",
    'planning': """
import miro_ball.launch.plan as plan
real = plan.make_plan
def interrupted(*args):
    os.kill(os.getpid(), signal.SIGINT)
    return real(*args)
plan.make_plan = interrupted
"""}


@pytest.mark.parametrize('when', INTERRUPTED)
def test_ctrl_c_while_it_imports_or_plans_ends_it_quietly(when):
    code = ('import os, runpy, signal, sys\n' + INTERRUPTED[when]
            + "sys.argv = ['launch', 'football', '--print']\n"
            "runpy.run_module('miro_ball.launch', run_name='__main__', alter_sys=True)\n")
    done = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                          timeout=60)
    assert (done.returncode, done.stdout, done.stderr) == (130, '', '')


def test_arguments_the_files_do_not_take_are_refused(sample, tmp_path):
    with pytest.raises(LaunchError, match=r'declares no argument robto \(it takes robot, '):
        plan(sample, robto='x')
    with pytest.raises(LaunchError, match='who is not for the user to give: sample.launch'):
        plan(sample, who='x')
    write(tmp_path, 'child.launch.xml', CHILD)
    message = refusal(tmp_path, '<launch><include file="child.launch.xml"><arg name="who" '
                                'value="a"/><arg name="whom" value="b"/></include></launch>')
    assert 'passes whom, which child.launch.xml does not declare' in message


def test_an_unknown_package_or_executable_is_refused_in_one_line():
    with pytest.raises(LaunchError, match="package 'no_such_package' is not installed"):
        console_scripts('no_such_package')
    with pytest.raises(LaunchError, match="^package 'p{100}' not found"):  # was an OSError
        share_folder('p' * 300)  # $(find-pkg-share ...) of a name past 255 bytes
    with pytest.raises(LaunchError, match="package miro_ball has no executable 'miro_simm'"):
        command(Process('x', Path('f'), pkg='miro_ball', exec='miro_simm'))


def test_the_bundled_files_start_what_their_docs_say():
    names = [path.name for path in bundled()]
    assert names == ['demo.launch.yaml', 'football.launch.yaml', 'lab.launch.yaml',
                     'record.launch.yaml', 'sim.launch.xml']
    scripts = console_scripts('miro_ball')
    for path in bundled():
        given = {'bag': 'b'} if path.name.startswith('record') else {}
        for process in make_plan(path, given, share_folder, os.environ).processes:
            assert process.pkg == 'miro_ball' and process.exec in scripts, process
    football = make_plan(find('football'), {}, share_folder, os.environ).processes
    assert [p.label for p in football] == ['miro_sim'] + [
        f'miro0{n}/kick_blue_ball' for n in (1, 2, 3)] + ['miro_gui']
    assert ('world', 'football_pitch') in football[0].params
    assert [p.params for p in football[1:4]] == [
        (('mode', 'improved'), ('seed', str(n))) for n in (1, 2, 3)]
    quiet = make_plan(find('demo.launch.yaml'), {'gui': 'false'}, share_folder, os.environ)
    assert [p.exec for p in quiet.processes] == ['miro_sim', 'miro_animal']
    assert make_plan(find('record'), {}, share_folder, os.environ).missing == ['bag']


def test_every_node_of_the_bundled_files_ends_the_run_when_it_ends():
    """on_exit="shutdown" on every node: a refused miro_sim (exit 2) left kick_blue_ball
    driving another simulator on the domain under ros2 launch, which lets the others run
    unless a file says so; both launchers read it."""
    for path in bundled():
        plan = make_plan(path, {'bag': 'b'} if path.name.startswith('record') else {},
                         share_folder, os.environ)
        assert all(p.shutdown_on_exit for p in plan.processes), path.name


def run_cli(*args, env=None, cwd=None):
    return subprocess.run([sys.executable, '-m', 'miro_ball.launch', *args], capture_output=True,
                          text=True, env=env, cwd=cwd, timeout=60)  # a hang guard only


def test_help_lists_the_bundled_files_and_their_arguments_and_print_runs_nothing():
    shown = run_cli('--help')
    assert shown.returncode == 0
    assert 'football.launch.yaml\n    mode:=  (default improved) the controllers' in shown.stdout
    assert 'bag:=  (required) the bag folder' in shown.stdout
    printed = run_cli('football', 'gui:=false', '--print')
    assert printed.returncode == 0, printed.stderr
    assert [line.split()[0] for line in printed.stdout.splitlines()] == [
        '[miro_sim]', '[miro01/kick_blue_ball]', '[miro02/kick_blue_ball]',
        '[miro03/kick_blue_ball]']
    assert '--ros-args -r __ns:=/miro02 -p mode:=improved -p seed:=2' in printed.stdout


@pytest.mark.parametrize('args, words', [
    (['nosuch'], "no launch file 'nosuch' (a path, or one of miro_ball's: demo, football,"),
    (['record'], 'record.launch.yaml needs bag:=...'),
    (['lab', 'gui=false'], "'gui=false' is not name:=value"),
    (['lab', 'gui:=maybe'], "got 'maybe'"),
    # A name past 255 bytes was a traceback ('File name too long')
    (['x' * 300], "no launch file '" + 'x' * 200 + "' (a path, or one of"),
])
def test_a_bad_command_line_gets_one_line(args, words):
    refused = run_cli(*args, '--print')
    assert refused.returncode == 2 and refused.stdout == ''
    assert len(refused.stderr.splitlines()) == 1 and words in refused.stderr, refused.stderr


def test_an_installed_copy_has_its_launch_files_where_ros2_launch_looks(tmp_path):
    """pip puts setup.py's data files under the prefix's share/miro_ball, as colcon does:
    the copy finds them there by $AMENT_PREFIX_PATH, as ros2 launch does."""
    target = tmp_path / 'prefix'
    subprocess.run([sys.executable, '-m', 'pip', 'install', '-q', '--no-deps', '--target',
                    str(target), str(ROOT)], check=True, capture_output=True)
    installed = sorted(p.name for p in (target / 'share' / 'miro_ball' / 'launch').iterdir())
    assert installed == [path.name for path in bundled()]
    env = dict(os.environ, PYTHONPATH=str(target), AMENT_PREFIX_PATH=str(target))
    printed = run_cli('lab', '--print', env=env, cwd=tmp_path)
    assert printed.returncode == 0 and printed.stdout.count('\n') == 3, printed.stderr
    probe = subprocess.run([sys.executable, '-c', 'import miro_ball.launch.files as f; '
                            'print(f.__file__, f.share_folder("miro_ball"))'], env=env,
                           capture_output=True, text=True, check=True, cwd=tmp_path)
    assert probe.stdout.split() == [str(target / 'miro_ball' / 'launch' / 'files.py'),
                                    str(target / 'share' / 'miro_ball')]


def test_ros2s_own_launch_reads_every_bundled_file():
    """Where ROS 2's launch is installed (a full ROS 2; no wheel of it on PyPI), its own
    frontend parses each file: the files are ROS 2 launch files, not a dialect of ours."""
    pytest.importorskip('launch_ros')
    pytest.importorskip('launch_xml')
    pytest.importorskip('launch_yaml')
    from launch.frontend import Parser

    for path in bundled():
        entity, parser = Parser.load(str(path))
        assert parser.parse_description(entity).entities, path


def ros2_nodes(entities):
    """The node actions of a parsed launch description, groups' too (not includes': each
    bundled file is read on its own)."""
    from launch.actions import IncludeLaunchDescription
    from launch_ros.actions import Node

    for entity in entities:
        if isinstance(entity, Node):
            yield entity
        elif not isinstance(entity, IncludeLaunchDescription):
            yield from ros2_nodes(entity.get_sub_entities())


def test_ros2s_own_launch_reads_on_exit_shutdown_on_every_bundled_node():
    """Where ROS 2's launch is installed: its own frontend gives every node of our files a
    Shutdown on exit, so ros2 launch stops the rest when one ends, as ours does."""
    pytest.importorskip('launch_ros')
    pytest.importorskip('launch_xml')
    pytest.importorskip('launch_yaml')
    from launch.actions import Shutdown
    from launch.frontend import Parser

    for path in bundled():
        entity, parser = Parser.load(str(path))
        nodes = list(ros2_nodes(parser.parse_description(entity).entities))
        assert nodes, path.name
        for node in nodes:
            assert any(isinstance(action, Shutdown) for action in node.get_sub_entities()), \
                path.name


def test_docs_launch_md_lists_every_bundled_file_with_its_own_arguments():
    rows = {line.split('|')[1].strip(' `'): line
            for line in (ROOT / 'docs' / 'launch.md').read_text().splitlines()
            if line.startswith('| `') and '.launch.' in line.split('|')[1]}
    assert sorted(rows) == [path.name for path in bundled()]
    for path in bundled():
        own = [arg.name for arg in make_plan(path, {}, share_folder, os.environ).args.values()
               if arg.file == path]
        assert own and all(f'`{name}`' in rows[path.name] for name in own), path.name
