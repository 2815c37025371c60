"""The command lines of our nodes, as a user types them: the one place that says how a run
starts the simulator, a controller per robot, the GUI and the recorder.

A node that serves one robot is started in the robot's namespace (``-r __ns:=/<robot>``),
so every controller is ``/<robot>/kick_blue_ball`` and no two nodes of a run share a
name. The simulator names the world's unnamed robot from $MIRO_ROBOT_NAME, the
environment every node of the run shares.
"""
import sys

from miro_ball.controller.names import NODE_NAME as CONTROLLER
from miro_ball.miro.interface import robot_name

PY = sys.executable


def robot_names(world, parser):
    """The world's robot names, as the simulator will call them; a world that does not
    load, or a bad $MIRO_ROBOT_NAME, is the parser's one-line error."""
    from miro_sim_bullet.scene.world_file import load_world

    try:
        return [spec.name or robot_name() for spec in load_world(world).robots]
    except ValueError as err:  # WorldError, a bad name
        parser.error(str(err))


def controller_log(robot):
    """The log name of a robot's controller in a run."""
    return f'{CONTROLLER}_{robot}'


def controller_command(robot, mode='improved', seed=1):
    """kick_blue_ball driving robot, on simulated time."""
    return [PY, '-m', 'miro_ball', '--ros-args', '-r', f'__ns:=/{robot}',
            '-p', 'use_sim_time:=true', '-p', f'mode:={mode}', '-p', f'seed:={seed}']


def sim_command(world, renderer='auto', real_time_factor=1.0, overhead_rate=0.0,
                paused=False):
    """The simulator; paused: until someone calls its ~/pause service with false. Our runs
    claim a ROS domain of their own (common/isolation.py), so the simulator need not spend
    peer_check_s looking for another one there."""
    return [PY, '-m', 'miro_sim_bullet', '--ros-args', '-p', 'peer_check_s:=0',
            '-p', f'world:={world}',
            '-p', f'renderer:={renderer}', '-p', f'real_time_factor:={real_time_factor}',
            '-p', f'overhead_rate:={overhead_rate}', '-p', f'paused:={str(paused).lower()}']


def gui_command(port):
    return [PY, '-m', 'miro_ball.gui', '--port', str(port)]


def record_command(out):
    """The recorder, as it records by default: every topic but the raw eye images."""
    return [PY, '-m', 'miro_ball.record', '-o', str(out)]


def run_nodes(robots, world, renderer='auto', real_time_factor=1.0, overhead_rate=0.0,
              paused=False, mode='improved', seed=1, gui_port=None, record=None):
    """(log name, command) of every node of a run, in the order they are stopped: the GUI
    if gui_port is given (first: it may be driving a robot), a controller per robot (seeds
    seed, seed + 1, ...), the simulator, whose /clock they wait on, and the recorder if
    record (its bag folder) is given, last so that it records to the end."""
    gui = [('miro_gui', gui_command(gui_port))] if gui_port is not None else []
    controllers = [(controller_log(name), controller_command(name, mode, seed + index))
                   for index, name in enumerate(robots)]
    sim = ('miro_sim', sim_command(world, renderer, real_time_factor, overhead_rate, paused))
    recorder = [('record', record_command(record))] if record else []
    return gui + controllers + [sim] + recorder
