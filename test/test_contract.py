"""The controller contract without ROS: its values, detectors and controllers by name, the
example wag controller, the sim-time rule and --save-debug's bound."""
import dataclasses
import random
from pathlib import Path

import pytest

from miro_ball.bench.synthetic import Disc, render
from miro_ball.common.sim_time import set_on_command_line, sim_time_overrides
from miro_ball.controller.behaviour import (BehaviourParams, DEFAULT_CAMERA, DEFAULT_CAMERAS,
                                            ImprovedBehaviour, TutorialBehaviour)
from miro_ball.controller.contract import Action, Eye, Percepts
from miro_ball.controller.controllers import controller_class, make_controller
from miro_ball.controller.debug_folder import DebugFolder
from miro_ball.controller.detection import Ball, DetectionParams
from miro_ball.controller.detectors import DETECTORS, found_in, make_detectors, register
from miro_ball.controller.params import ControllerParams
from miro_ball.examples.controller_wag import Wag
from miro_ball.miro.constants import COSMETIC_CALIB


def percepts(t=0.0, left=None, right=None, **readings):
    eyes = tuple(Eye(camera, detections={'ball': found})
                 for camera, found in zip(DEFAULT_CAMERAS, (left, right)))
    return Percepts(t, eyes, **readings)


def test_an_action_publishes_only_what_it_sets():
    action = Action(wheels=(0.1, 0.1))
    assert action.head is action.cosmetic is action.illum is action.tone is None
    assert action.messages == () and action.state == ''
    with pytest.raises(dataclasses.FrozenInstanceError):
        action.wheels = (0.0, 0.0)


def test_percepts_have_one_eye_per_eye_and_say_what_each_found():
    ball = Ball(0.1, 0.0, 0.03)
    seen = percepts(1.5, None, ball, cliff=(1.0, 1.0), sonar=0.3)
    assert seen.found('ball') == (None, ball)
    assert seen.found('smell') == (None, None)  # not run: nothing found
    assert seen.cameras == DEFAULT_CAMERAS and seen.sonar == 0.3 and seen.touch_head is None
    with pytest.raises(ValueError, match='one Eye per eye'):
        Percepts(0.0, (Eye(DEFAULT_CAMERA),))


def test_an_answer_handed_back_again_is_said_to_be_from_the_frame_it_was_found_in():
    """A detector that looks at one frame in two hands back its last answer in between (as
    the face detector does, face_every): the eye says it was found in the frame it looked
    at; a fresh answer, or nothing found, is of its own frame."""
    looks, answer = iter(range(100)), {}

    def every_other():
        look = next(looks)
        if look % 2 == 0:
            answer['last'] = ('a face', look)
        return answer['last']
    before, said = None, []
    for stamp in (1.0, 1.1, 1.2, 1.3):
        found = {'face': every_other(), 'ball': None}
        carried = found_in(found, before)
        eye = Eye(DEFAULT_CAMERA, None, found, stamp, carried)
        said.append((eye.found_at('face'), eye.found_at('ball')))
        before = (found, stamp, carried)
    assert said == [(1.0, 1.0), (1.0, 1.1), (1.2, 1.2), (1.2, 1.3)]
    assert Eye(DEFAULT_CAMERA).found_at('face') is None
    # Nothing found is of its own frame: () is one object, whichever frame found nothing.
    assert found_in({'face': ()}, ({'face': ()}, 1.0, {})) == {}


def test_the_ball_detector_is_one_by_name_among_others():
    frame = render(640, 360, [Disc(400, 200, 30)], seed=1)
    detectors = make_detectors(('ball',), DetectionParams())
    found = detectors['ball'](frame, DEFAULT_CAMERA)
    assert found.x == pytest.approx(80 / 640, abs=0.01)
    assert found.r == pytest.approx(30 / 640, abs=0.01)
    assert detectors['ball'](render(640, 360, [], seed=1), DEFAULT_CAMERA) is None
    with pytest.raises(ValueError, match="no detector named 'smell' .*known: .*ball"):
        make_detectors(('ball', 'smell'), DetectionParams())


def test_a_registered_detector_is_run_by_name():
    register('brightest', lambda params: lambda image, camera: int(image.max()))
    try:
        frame = render(640, 360, [], seed=1)
        assert make_detectors(('brightest',), DetectionParams())['brightest'](
            frame, DEFAULT_CAMERA) == frame.max()
    finally:
        del DETECTORS['brightest']


@pytest.mark.parametrize('mode,cls', [
    ('tutorial', TutorialBehaviour), ('improved', ImprovedBehaviour), ('wag', Wag),
    ('miro_ball.examples.controller_wag:Wag', Wag)])
def test_a_mode_names_a_controller(mode, cls):
    assert controller_class(mode) is cls
    assert isinstance(make_controller(mode, BehaviourParams()), cls)
    assert ControllerParams(mode=mode).mode == mode


class NeedsASmell:
    detectors = ('ball', 'smell')

    def act(self, percepts):
        return Action()


@pytest.mark.parametrize('mode,said', [
    ('clever', 'must be one of tutorial, improved, wag or module:Class'),
    ('no_such_module:Thing', 'cannot import no_such_module'),
    ('miro_ball.examples.controller_wag:Nope', 'has no controller class Nope'),
    ('miro_ball.controller.contract:Action', 'has no controller class Action'),
    ('test_contract:NeedsASmell', "no detector named 'smell' .*known: .*ball")])
def test_a_mode_that_names_no_controller_is_refused(mode, said):
    with pytest.raises(ValueError, match=said):
        ControllerParams(mode=mode)


def test_wag_wags_only_while_the_ball_is_seen():
    wag = Wag(BehaviourParams())
    assert wag.detectors == ('ball',)
    rng = random.Random(3)
    swings = set()
    for i in range(200):
        t = i * 0.02
        ball = Ball(rng.uniform(-0.5, 0.5), 0.0, 0.03) if rng.random() < 0.5 else None
        left, right = (ball, None) if rng.random() < 0.5 else (None, ball)
        action = wag.act(percepts(t, left, right))
        assert action.wheels == (0.0, 0.0) and all(0.0 <= v <= 1.0 for v in action.cosmetic)
        others = action.cosmetic[:1] + action.cosmetic[2:]
        assert others == COSMETIC_CALIB[:1] + COSMETIC_CALIB[2:]
        if ball is None:
            assert action.cosmetic == COSMETIC_CALIB and action.state == 'watching'
        else:
            assert action.state == 'wagging'
            swings.add(round(action.cosmetic[1], 1))
    assert min(swings) <= 0.1 and max(swings) >= 0.9  # a wag, side to side


@pytest.mark.parametrize('args,set_there', [
    (['prog'], False),
    (['prog', '--ros-args', '-p', 'use_sim_time:=false'], True),
    (['prog', '--ros-args', '--param', 'use_sim_time:=true'], True),
    (['prog', '--ros-args', '-p', 'mode:=tutorial'], False),
    (['prog', '-p', 'use_sim_time:=false'], False),  # not a ROS argument
    (['prog', '--ros-args', '-r', '__ns:=/x', '--', '-p', 'use_sim_time:=false'], False),
    (['prog', '--ros-args', '-p'], False)])
def test_sim_time_is_the_default_the_command_line_can_change(args, set_there):
    assert set_on_command_line(args) is set_there
    overrides = sim_time_overrides(args=args)
    if set_there:
        assert overrides == []
    else:
        assert [(p.name, p.value) for p in overrides] == [('use_sim_time', True)]


def test_debug_folder_keeps_the_newest(tmp_path):
    folder = DebugFolder(str(tmp_path), keep=3)
    for i in range(10):
        folder.save('f%02d.jpg' % i, b'x' * i)
    assert sorted(p.name for p in tmp_path.iterdir()) == ['f07.jpg', 'f08.jpg', 'f09.jpg']
    (tmp_path / 'f07.jpg').unlink()  # tidied by hand meanwhile
    folder.save('f10.jpg', b'')
    assert sorted(p.name for p in tmp_path.iterdir()) == ['f08.jpg', 'f09.jpg', 'f10.jpg']


def test_docs_show_the_wag_controller_as_it_is():
    root = Path(__file__).resolve().parents[1]
    source = (root / 'miro_ball' / 'examples' / 'controller_wag.py').read_text()
    code = source.split('"""', 2)[2].strip()  # after the module docstring
    assert '```python\n' + code + '\n```' in (root / 'docs' / 'controller.md').read_text()
    assert len(code.splitlines()) <= 25
