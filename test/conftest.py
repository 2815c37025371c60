"""Shared fixtures. ROS tests run in their own rclpy Context on a ROS domain
chosen per test process, discovery limited to this host, so parallel runs and
other ROS processes on the machine never see each other's topics."""
import os

import pytest

from miro_ball.common.isolation import limit_discovery, private_domain

limit_discovery()
os.environ['ROS_DOMAIN_ID'] = str(private_domain())

# Every test module is in one tier, so a contributor can run one: pytest -m unit.
TIERS = {
    'unit': ('pure logic, PyBullet and the renderers in-process; no ROS graph (about a minute)',
             ('test_behaviour', 'test_convert', 'test_detection', 'test_eye_geometry',
              'test_gui_protocol', 'test_interface', 'test_isolation', 'test_jpeg',
              'test_layering', 'test_param_bounds', 'test_processes', 'test_rendering',
              'test_report', 'test_shm', 'test_sim_physics', 'test_world_file',
              'test_world_fuzz', 'test_kc', 'test_camera_model', 'test_gaze', 'test_class_report',
              'test_pose_controller', 'test_floor_map', 'test_scene_markers', 'test_touch',
              'test_pictures', 'test_gui_scene', 'test_eye_pipeline', 'test_held_command',
              'test_judge', 'test_sandbox_args', 'test_param_overrides',
              'test_speaker', 'test_contract', 'test_rotations', 'test_checks',
              'test_grade_report', 'test_soak_verdict', 'test_packaging', 'test_record_parts',
              'test_ros2_convert', 'test_build_interfaces', 'test_body', 'test_hearing',
              'test_animal_parts', 'test_throttle', 'test_sound_files', 'test_docs',
              'test_gui_pairing', 'test_faces', 'test_learn', 'test_learn_multi',
              'test_learn_train', 'test_learn_vector', 'test_launch_files',
              'test_sim_control', 'test_posix_regex')),
    'ros': ('nodes in-process on executors of their own, a process or two beside them',
            ('test_clients', 'test_controller_node', 'test_fuzz_params', 'test_fuzz_topics',
             'test_gui_bridge', 'test_multi_robot', 'test_sim_executor', 'test_sim_node',
             'test_client_map', 'test_robot_object', 'test_scene', 'test_grade_host',
             'test_callback_faults', 'test_sensors_package', 'test_ros2_cli', 'test_foxglove',
             'test_tf', 'test_audio_clients', 'test_animal', 'test_readers',
             'test_ros2_sim_interfaces', 'test_sim_standard_hostile', 'test_sim_files')),
    'e2e': ('whole runs as processes: demo, grader, recorder, tutorial, soak, packaging',
            ('test_closed_loop', 'test_lab', 'test_grade', 'test_launch',
             'test_record', 'test_restart', 'test_scenario_bench',
             'test_signals', 'test_sim_domain', 'test_soak', 'test_tutorial', 'test_grade_class',
             'test_grade_ray', 'test_refusals', 'test_learn_ros', 'test_learn_ray',
             'test_sim_standard', 'test_demo_mode_run')),
    'browser': ('the GUI in Debian\'s chromium through Playwright', ('test_gui_browser',)),
    'netns': ('hosts in network namespaces (root)', ('test_two_hosts',)),
}
TIER_OF = {module: tier for tier, (_, modules) in TIERS.items() for module in modules}


def pytest_configure(config):
    for tier, (about, _) in TIERS.items():
        config.addinivalue_line('markers', f'{tier}: {about}')


# The files that take longest (20 s to 90 s each in a full run, 2026-11-25), longest first:
# under ./dev.sh test (xdist, a file to a worker, the next file to whichever is free) a long
# file collected last ran alone at the end while the other worker idled; longest first, the
# short ones fill in at the end.
SLOWEST_FIRST = ('test_tutorial', 'test_grade_class', 'test_gui_browser', 'test_record',
                 'test_signals', 'test_grade_ray', 'test_clients', 'test_ros2_cli',
                 'test_closed_loop', 'test_tf', 'test_lab', 'test_animal', 'test_robot_object',
                 'test_sim_domain', 'test_grade', 'test_soak', 'test_restart')


def pytest_collection_modifyitems(config, items):
    for item in items:
        tier = TIER_OF.get(item.path.stem)
        if tier is None:
            raise pytest.UsageError(f'{item.path.name} is in no test tier: add it to TIERS in '
                                    'test/conftest.py')
        item.add_marker(tier)
    rank = {name: index for index, name in enumerate(SLOWEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.stem, len(SLOWEST_FIRST)))  # stable


@pytest.fixture(scope='session', autouse=True)
def shared_memory_janitor():
    """Tests kill ROS processes on purpose: their Fast DDS files go at the end of the run."""
    from miro_ball.common.shm import SharedMemoryJanitor

    janitor = SharedMemoryJanitor()
    yield janitor
    janitor.clean()


@pytest.fixture
def ros_context():
    """A fresh, initialised rclpy Context (never the global one)."""
    import rclpy
    from rclpy.context import Context

    context = Context()
    rclpy.init(context=context, domain_id=int(os.environ['ROS_DOMAIN_ID']))
    yield context
    rclpy.try_shutdown(context=context)


@pytest.fixture
def executor(ros_context):
    """A SingleThreadedExecutor on the test's own context."""
    from rclpy.executors import SingleThreadedExecutor

    ex = SingleThreadedExecutor(context=ros_context)
    yield ex
    ex.shutdown(timeout_sec=1.0)


@pytest.fixture
def make_sim(ros_context, executor):
    """make_sim(name=value, ..., robot=None, privileged=True): a simulator node in-process,
    paused (the test steps it, rostools.advance_ticks), with those parameters and the world's
    unnamed robot named robot (as --robot does); destroyed after the test."""
    from rclpy.parameter import Parameter

    from miro_sim_bullet.ros.node import SimNode

    made = []

    def make(robot=None, privileged=True, **params):
        params = {'paused': True, 'world': 'miro', **params}
        made.append(SimNode(context=ros_context, robot=robot, privileged=privileged,
                            parameter_overrides=[Parameter(name, value=value)
                                                 for name, value in params.items()]))
        executor.add_node(made[-1])
        return made[-1]
    yield make
    for node in made:
        executor.remove_node(node)
        node.destroy_node()


@pytest.fixture
def paused_sim(make_sim):
    """The simulator node in-process on the default world, paused."""
    return make_sim()


@pytest.fixture(scope='module')
def marked_floor():
    """(a SimWorld 'empty' with a red floor mark, the mark's body, its Cameras)"""
    from floor_mark import marked_world

    with marked_world() as marked:
        yield marked
