"""Demo mode's controller: MiRo as a small animal, one Percepts in, one Action out.

Each tick (time passed in, no ROS here) the parts run in turn:

    senses -> attention -> (feel, affect, sleep) -> action selection -> reflexes
           -> expression -> voice

senses.py turns detections and the sound heard into stimuli around MiRo; attention.py
paints them on the priority map, whose peak is the target; feel.py reads strokes, pets
and hits from the touch pads; affect.py and sleep.py move emotion, mood, wakefulness and
pressure; actions.py says what each action wants and does, selection.py picks one; the
reflexes here (cliff, sonar, sleep, the flags) have the last word on the wheels;
express.py and voice.py show the state. Every part is replaceable: the selector by the
`selector` parameter, any other by a subclass (docs/demo_mode.md).
"""
import math

import numpy as np

from miro_ball.animal.actions import ACTIONS, make_actions, Situation
from miro_ball.animal.affect import AffectModel, Events
from miro_ball.animal.attention import PriorityMap
from miro_ball.animal.express import Expression
from miro_ball.animal.feel import Feel
from miro_ball.animal.own_motion import OwnMotion
from miro_ball.animal.params import Config, FLAG_LETTERS
from miro_ball.animal.selection import selector_class
from miro_ball.animal.senses import Senses
from miro_ball.animal.sleep import SleepModel
from miro_ball.animal.voice import as_tone, length_s, vocalise
from miro_ball.controller.contract import Action
from miro_ball.miro.constants import (CLIFF_THRESHOLD, KIN_CALIB_RAD, LIFT_RAD_CALIB,
                                      PLATFORM_TICK_S, TILT_RAD)
from miro_ball.miro.kinematics import (clamp_wheel_speeds, cmd_vel2wheel_speed,
                                      wheel_speed2cmd_vel)

SONAR_BAND_M = (0.10, 0.25)  # the MDK's sonar modulation: stop at the near end, free beyond
SHUN_SPEED, SHUN_TURN = 0.1, 1.5  # backing off a drop, m/s and rad/s
LOUD = 0.5  # a sound this loud (0..1 of the loud range) wakes and startles
MAX_DT = 0.2  # a longer gap (a paused simulator) counts as this much
SEEN = ('ball', 'face', 'tag', 'motion')  # the detectors demo mode runs on each eye
SWITCHED_BY = {'ball': 'salience_ball', 'face': 'salience_faces', 'motion': 'salience_motion',
               'sound': 'salience_sound'}
HEARD_FOR_S = 0.6  # a sound is in the percepts this long after it ends (stale_s, a block)


class Animal:
    """Percepts in, Action out (controller/contract.py), with its state to show:
    emotion, mood (affect.Affect), sleep (SleepState), priorities and selected (index into
    ACTIONS), peak and target (attention.Peak), stimuli of the latest tick."""

    hears = True

    def __init__(self, config=Config(), selector='basal_ganglia', seed=0):
        if not isinstance(config, Config):
            # e.g. `-p mode:=...:Animal` of kick_blue_ball, whose parameters are not demo
            # mode's: refused, never run on defaults the user did not choose.
            raise ValueError('demo mode is built from its own parameters (animal.params.Config), '
                             f'not {type(config).__name__}: run it as python -m miro_ball.animal')
        self.rng = np.random.default_rng(seed)
        self.config = config
        self.map = PriorityMap(config.spatial)
        self.feel = Feel(config.affect)
        self.affect = AffectModel(config.affect, config.flags)
        self.sleep = SleepModel(config.sleep)
        self.actions = make_actions(config.action, config.flags)
        self.selector = selector_class(selector)(config.action, self.rng)
        self.express = Expression(config.express, config.flags, self.rng)
        self.senses = Senses(config.spatial, config.action)
        self.own_motion = OwnMotion()
        self.selected, self.priorities = None, [0.0] * len(ACTIONS)
        self.peak = self.target = None
        self.stimuli = []
        self.loudness = 0.0
        self._last_t = None
        self._moved_at = self._target_at = 0.0
        self._forward = 0.0
        self._head = (LIFT_RAD_CALIB, 0.0, 0.0)  # lift, yaw, pitch told last
        self._voice_ready_at = 0.0
        self._vocalising_until = -math.inf
        self._had_motion = False
        self._was_roused = False
        self._was_asleep = False

    @property
    def detectors(self):
        return tuple(kind for kind in SEEN if self._noticed(kind))

    def _noticed(self, kind):
        """Whether a kind of thing draws attention (its switch, if it has one, is on)."""
        switch = SWITCHED_BY.get(kind)
        return switch is None or getattr(self.config.flags, switch)

    def configure(self, config):
        """New parameters, the state kept (a live parameter change)."""
        self.config = config
        self.map.params = self.senses.spatial = config.spatial
        self.senses.action = config.action
        self.feel.params = config.affect
        self.affect.params, self.affect.flags = config.affect, config.flags
        self.sleep.params = config.sleep
        self.express.params, self.express.flags = config.express, config.flags
        self.selector.params = config.action
        for action in self.actions:
            action.params, action.flags = config.action, config.flags

    @property
    def flag_bits(self):
        """The switches on, a bit each in FLAG_LETTERS order (core/animal/state's flags)."""
        return sum(1 << i for i, (_, name, _) in enumerate(FLAG_LETTERS)
                   if getattr(self.config.flags, name))

    @property
    def selected_name(self):
        return ACTIONS[self.selected] if self.selected is not None else ''

    @property
    def asleep(self):
        return self.config.flags.sleep and self.sleep.asleep

    # -- the tick ----------------------------------------------------------------------------
    def act(self, percepts):
        t = percepts.t
        dt = PLATFORM_TICK_S if self._last_t is None else min(MAX_DT, max(0.0, t - self._last_t))
        self._last_t = t
        flags = self.config.flags
        joints = percepts.joints or KIN_CALIB_RAD
        self.own_motion.tick(t, joints)

        still = t - self._moved_at >= self.config.spatial.motion_still_s
        stimuli = [s for s in self.senses.sights(percepts, include_motion=still,
                                                 motion=self.own_motion)
                   if self._noticed(s.kind)]
        heard = self.senses.sound(percepts.sound, joints)
        vocalising = t < self._vocalising_until
        # MiRo's own voice is the loudest thing it hears: it neither startles nor wakes it.
        self.loudness = heard.strength if heard is not None and not vocalising else 0.0
        if heard is not None and self._noticed('sound'):
            stimuli.append(heard)
        self.stimuli = stimuli
        self.peak = self.map.update(dt, stimuli, self_noisy=vocalising)
        self.target = self.map.target(self.peak)
        if self.target is not None:
            self._target_at = t

        motion = any(s.kind == 'motion' for s in stimuli)
        startled = motion and not self._had_motion
        self._had_motion = motion
        touches = self.feel.feel(percepts.touch_head, percepts.touch_body)
        light = float(np.mean(percepts.light)) if percepts.light else 0.5
        loud = self.loudness >= LOUD
        # A touch or a loud sound wakes MiRo when it begins (not again every tick it lasts).
        roused = touches.touched or loud
        woken = roused and not self._was_roused
        self._was_roused = roused
        if flags.sleep:
            stimulation = min(1.0, touches.touched + self.loudness + 0.5 * (self.target
                                                                            is not None))
            self.sleep.step(dt, stimulation, woken=woken)
        wakefulness = self.sleep.state.wakefulness if flags.sleep else 1.0
        self.affect.step(dt, Events(touches.strokes, touches.pet, touches.hits,
                                    self.loudness, startled, light), wakefulness)
        emotion = self.affect.emotion

        situation = Situation(t, dt, self.target, emotion.valence, emotion.arousal,
                              percepts.sonar, t - self._target_at, self._forward)
        self.priorities = [action.priority(situation) for action in self.actions]
        chosen = self.selector.select(t, self.priorities)
        if chosen != self.selected:
            if self.selected is not None:
                self.actions[self.selected].stop(situation)
            self.actions[chosen].start(situation)
            self.selected = chosen
        action = self.actions[chosen]
        motor = action.motor(situation)
        if action.finished and t - action.started >= self.config.action.min_duration_s:
            action.stop(situation)  # (a pattern done sooner holds its end till then)

        wheels = self._reflexes(motor.forward, motor.turn, percepts, wakefulness)
        self.own_motion.told(wheel_speed2cmd_vel(clamp_wheel_speeds(*wheels))[1])
        head = self._head_pose(motor, t, wakefulness)
        shown = self.express.step(t, dt, emotion.valence, emotion.arousal, wakefulness,
                                  touches.touched)
        said = self._voice(t, touches, loud)
        return Action(wheels=wheels, head=head, cosmetic=shown.cosmetic, illum=shown.illum,
                      state=self.selected_name, **said)

    def _reflexes(self, forward, turn, percepts, wakefulness):
        """The lower level: flags, sonar, cliff and sleep have the last word on the wheels."""
        flags = self.config.flags
        if not flags.translation:
            forward = 0.0
        if not flags.rotation:
            turn = 0.0
        if flags.sonar_modulation and percepts.sonar is not None and forward > 0:
            near, far = SONAR_BAND_M
            forward *= min(1.0, max(0.0, (percepts.sonar - near) / (far - near)))
        cliff = percepts.cliff
        if cliff is not None and min(cliff) < CLIFF_THRESHOLD:
            if flags.shun_cliffs:
                # back off and turn away from the side that sees the drop
                forward = -SHUN_SPEED
                turn = -SHUN_TURN if cliff[0] < cliff[1] else SHUN_TURN
            elif flags.cliff_reflex:
                forward = min(forward, 0.0)
        if flags.sleep:
            low = self.config.sleep.asleep_below
            gate = min(1.0, max(0.0, (wakefulness - low) / max(1e-6, 0.5 - low)))
            forward, turn = forward * gate, turn * gate
        self._forward = forward
        if abs(forward) > 0.01 or abs(turn) > 0.05:
            self._moved_at = percepts.t
        return cmd_vel2wheel_speed(forward, turn)

    def _head_pose(self, motor, t, wakefulness):
        if not self.config.flags.neck:
            return None
        lift, yaw, pitch = self._head
        lift = motor.lift if motor.lift is not None else lift
        yaw = motor.yaw if motor.yaw is not None else yaw
        pitch = motor.pitch if motor.pitch is not None else pitch
        if abs(yaw - self._head[1]) > 0.005:
            self._moved_at = t
        self._head = (lift, yaw, pitch)
        if self.config.flags.sleep:
            lift, pitch = self.express.posture(t, lift, pitch, wakefulness)
            yaw *= wakefulness
        return (TILT_RAD, lift, yaw, pitch)

    def _voice(self, t, touches, loud):
        """A vocalisation now and then: pleased when stroked, hurt, startled, waking."""
        asleep = self.asleep
        woke, self._was_asleep = self._was_asleep and not asleep, asleep
        emotion = self.affect.emotion
        pleased = touches.strokes and emotion.valence > 0.1
        occasion = pleased or touches.hits or (loud and not asleep) or woke
        express = self.config.express
        if not (self.config.flags.voice and occasion and t >= self._voice_ready_at):
            return {}
        self._voice_ready_at = t + express.voice_refractory_s
        # Heard until the last block of it is out of date (stale_s of the node: 0.5 s).
        self._vocalising_until = t + length_s(emotion.valence) + HEARD_FOR_S
        if express.voice_via == 'tone':
            return {'tone': as_tone(emotion.valence, emotion.arousal, express.voice_volume)}
        samples = vocalise(emotion.valence, emotion.arousal, express.voice_volume, self.rng)
        return {'stream': tuple(int(v) for v in samples)}

    # -- from clients ------------------------------------------------------------------------
    def adjust(self, emotion=None, mood=None, sleep=None):
        """A client's nudge (core/animal/adjust): each a pair of (data, gamma) pairs, for
        (valence, arousal) or (wakefulness, pressure)."""
        if emotion is not None:
            self.affect.adjust('emotion', *emotion)
        if mood is not None:
            self.affect.adjust('mood', *mood)
        if sleep is not None:
            self.sleep.adjust(*sleep)
