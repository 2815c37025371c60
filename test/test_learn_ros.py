"""What is learnt in an environment behaves the same on the ROS simulator: seeded KickBall
episodes, the same controller class, in the environment and as the controller node on the
stepped ROS simulator (the grader's placement of the seed in both); the eyes of both doors
agree when the environment's options are the simulator's and the host's; and a policy
folder the node cannot use is refused at start."""
import math
import os
from types import SimpleNamespace

from miro_ball.controller.behaviour import BehaviourParams, make_behaviour
from miro_ball.controller.contract import Action
from miro_ball.controller.params import ControllerParams, detection_params
from miro_ball.learn.controllers import run_controller
from miro_ball.learn.env import MiroEnv
from miro_ball.policy.controller import POLICY_ENV, PolicyController
from miro_ball.learn.tasks.kick_ball import KickBall
from miro_ball.run.episode import run_episode
from miro_ball.run.placements import placements
from miro_ball.run.stepped_rig import SteppedRig
from program import Program

LIMIT_S = 20.0
EYES = (160, 90)
# The ROS simulator's eyes are 640x360 JPEGs at 15 Hz; the environment's are drawn every
# tick: a controller that decides every tick kicks a few ticks apart, never more.
SAME_KICK_WITHIN_S = 0.5
POLICY = 'miro_ball.policy.controller:PolicyController'


def both(context, mode, controller, seed):
    """(the ROS episode's EpisodeResult, the environment's info) of one seeded episode."""
    on_ros = run_episode(SteppedRig(context, mode=mode, seed=1, quiet=True),
                         placements(1, seed=seed)[0], limit_s=LIMIT_S)
    env = MiroEnv(KickBall(limit_s=LIMIT_S), eyes=EYES)
    _, _, here = run_controller(env, controller, seed=seed)
    env.close()
    return on_ros, here


def test_the_environment_and_the_ros_simulator_agree_on_a_seeded_kick(ros_context):
    on_ros, here = both(ros_context, 'improved',
                        make_behaviour('improved', BehaviourParams(seed=1)), seed=2)
    assert on_ros.kicked and here['kicked'], (on_ros, here)
    assert not on_ros.fell and not here['fell']
    assert abs(on_ros.time_to_kick - here['kick_time']) <= SAME_KICK_WITHIN_S, (on_ros, here)


def test_the_trained_policy_kicks_as_the_controller_node_on_the_ros_simulator(ros_context):
    """The policy `python -m miro_ball.learn.train kick_ball` trained (the bundled one), run
    by `python -m miro_ball --ros-args -p mode:=...PolicyController`. It decides every 100 ms
    on the freshest frame, so the moment the 15 Hz JPEGs reach it shifts its turns a little
    and the kick comes at another time (seconds apart at most, over seeds 1 to 9)."""
    for seed in (4, 7):
        on_ros, here = both(ros_context, POLICY, PolicyController(), seed)
        assert on_ros.kicked and here['kicked'], (seed, on_ros, here)
        assert not on_ros.fell and not here['fell']


# The eyes in both doors (docs/learning.md): the ROS simulator's defaults (640x360, 15 Hz,
# JPEG quality 80; stepped, an instant's images go out before its /clock: no latency), and
# detection settings of the host's other than its defaults, given to both as -p overrides.
SIM_EYES = dict(eyes=(640, 360), camera_rate=15.0, jpeg_quality=80, latency_s=0.0)
DETECTION = (('sat_min', 60), ('hough_param2', 12.0))
# The grader's placement of this seed, as KickBall's reset puts it: the ball in view of both
# eyes with the head in the host's start pose. MiRo holds still meanwhile.
SEED = 19
TICKS = 40
# The ball's centre and radius (the tutorial's units: pixels / frame width) may differ by
# one pixel of a 640-wide frame. Both doors draw the same world with the same renderer and
# the same lens, encode with the same function and decode with the same one, so a still
# scene gives the very same pixels (measured: identical); the pixel is for the physics of
# two worlds built apart, whose resting bodies may differ in the last digits.
WITHIN = 1 / 640


def eyes_on_ros(context):
    """[(t, (left, right) (stamp, ball))] each tick, from the controller host's percepts on
    the stepped ROS simulator, the host holding the head pose all along; and the host's
    DetectionParams."""
    host_params = [('head_hold_s', 60.0), *DETECTION]
    rig = SteppedRig(context, mode='tutorial', quiet=True, controller_params=host_params)
    seen = []
    try:
        rig.open()
        rig.place(placements(1, seed=SEED)[0])
        rig.wait_for_controllers()
        rig.start()
        host = rig.controllers[rig.sim.robot.name]
        for _ in range(TICKS):
            rig.advance()
            percepts = host.percepts(host.last_tick)
            seen.append((round(rig.sim.time, 6),
                         tuple((eye.stamp, eye.found('ball')) for eye in percepts.eyes)))
        return seen, host.detection_params
    finally:
        rig.close(SimpleNamespace())


def eyes_in_the_environment(**options):
    """The same from KickBall's environment reset with the seed (its settling as SteppedRig's),
    its robot told the host's hold pose every step."""
    env = MiroEnv(KickBall(), **options)
    try:
        env.reset(seed=SEED)
        lift = math.radians(ControllerParams().head_lift_deg)
        hold = Action(wheels=(0.0, 0.0), head=(0.0, lift, 0.0, 0.0))
        seen = []
        for _ in range(TICKS):
            env.step_action(hold)
            seen.append((round(env.rig.t, 6), tuple((eye.stamp, eye.found('ball'))
                                                    for eye in env.percepts().eyes)))
        return seen
    finally:
        env.close()


def test_the_eyes_of_both_doors_agree_when_the_environments_options_are_the_simulators(
        ros_context):
    """One seed's scene through both doors: the controller host's percepts (the simulator's
    JPEGs at its camera instants, its detectors with its parameters) and the Gymnasium
    environment's with the simulator's camera_rate and jpeg_quality and the host's
    detection settings (controller.params.detection_params of the same -p overrides): the
    same frames' stamps at every tick, and the same ball within a pixel. The environment's
    default eyes (drawn every step, uncompressed) see other instants."""
    args = ['--ros-args'] + [part for name, value in DETECTION
                             for part in ('-p', f'{name}:={value}')]
    on_ros, host_detection = eyes_on_ros(ros_context)
    assert detection_params(args) == host_detection
    here = eyes_in_the_environment(detection=detection_params(args), **SIM_EYES)
    # The simulator's first instant after the placement falls on the first step it takes
    # (SteppedRig settles the world outside its schedule); from the next one on, both doors
    # have the same instants.
    compared = [(t, ros, env) for (t, ros), (_, env) in zip(on_ros, here) if t > 0.27]
    assert len(compared) == TICKS - 3
    for t, ros, env in compared:
        for (ros_stamp, ros_ball), (env_stamp, env_ball) in zip(ros, env):
            assert ros_ball is not None and env_ball is not None, (t, ros, env)
            assert abs(ros_stamp - env_stamp) < 1e-6, (t, ros, env)
            assert all(abs(a - b) <= WITHIN for a, b in zip(ros_ball, env_ball)), (t, ros, env)
    assert len({stamp for _, ros, _ in compared for stamp, _ in ros}) < len(compared) / 2
    every_step = eyes_in_the_environment(eyes=SIM_EYES['eyes'])
    assert all(abs(eyes[0][0] - t) < 1e-6 for t, eyes in every_step)


def test_a_policy_file_that_is_a_fifo_is_refused_at_start(tmp_path, monkeypatch):
    """MIRO_POLICY naming a folder whose policy.json is a FIFO held the controller node at
    start for ever, deaf to Ctrl+C and SIGTERM."""
    os.mkfifo(tmp_path / 'policy.json')
    monkeypatch.setenv(POLICY_ENV, str(tmp_path))
    code, output = Program('miro_ball', '--ros-args', '-p', f'mode:={POLICY}',
                           guard_s=60).finish()
    assert code == 2 and len(output.strip().splitlines()) == 1, output
    assert "policy.json: 'policy.json' is not a regular file" in output
