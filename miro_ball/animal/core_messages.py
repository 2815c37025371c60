"""Demo mode's state as the MDK's messages (miro2_msg), and the adjust message back.

Plain functions of the Animal's state and the percepts: no node, no clock.
"""
import math

from miro_ball.animal.actions import ACTIONS
from miro_ball.miro.checks import finite


def animal_state(animal, stamp_s=None):
    from miro2_msg.msg import Affect, AnimalState, Sleep

    e, m, s = animal.affect.emotion, animal.affect.mood, animal.sleep.state
    return AnimalState(
        flags=animal.flag_bits, emotion=Affect(valence=e.valence, arousal=e.arousal),
        mood=Affect(valence=m.valence, arousal=m.arousal),
        sleep=Sleep(wakefulness=s.wakefulness, pressure=s.pressure),
        time_of_day=((stamp_s or 0.0) / 86400.0) % 1.0, sound_level=float(animal.loudness))


def inhibition(animal):
    return [0.0 if i == animal.selected else 1.0 for i in range(len(ACTIONS))]


def priority_peak(peak):
    """PriorityPeak of attention's Peak (stream_index -1: the map, not an eye's image)."""
    from miro2_msg.msg import PriorityPeak

    if peak is None:
        return PriorityPeak(stream_index=-1, actioned=0)
    return PriorityPeak(stream_index=-1, height=float(peak.height), size=float(peak.span),
                        azim=float(peak.azimuth), elev=float(peak.elevation),
                        size_norm=float(peak.span / math.pi),
                        range=float(peak.range if peak.range is not None else -1.0),
                        actioned=1)


def objects(eye_index, eye):
    """Objects of one eye's detections (contract.Eye), normalised as the MDK's: image
    coordinates 0..1 from the top left."""
    from miro2_msg.msg import ObjectBall, ObjectFace, ObjectTag, Objects

    width, height = eye.camera.width, eye.camera.height

    def image(sight):
        return [sight.x + 0.5, 0.5 - sight.y * width / height]

    msg = Objects(stream_index=eye_index)
    ball = eye.found('ball')
    if ball is not None:
        msg.balls = [ObjectBall(conf=1.0, centre=image(ball), radius=float(ball.r))]
    for face in eye.found('face') or ():
        (u, v), size = image(face), [face.size, face.size * width / height]
        msg.faces.append(ObjectFace(conf=float(face.conf), corner=[u - size[0] / 2,
                                                                   v - size[1] / 2],
                                    size=size))
    for tag in eye.found('tag') or ():
        msg.tags.append(ObjectTag(conf=float(tag.conf), id=int(tag.id), centre=image(tag)))
    return msg


def adjust_pairs(msg):
    """AnimalAdjust -> keyword arguments of Animal.adjust, each (data, gamma) pair checked
    finite; ValueError in one line otherwise."""
    def pair(adjust):
        if not finite(adjust.data, adjust.gamma):
            raise ValueError('an Adjust must be finite, got data %r gamma %r'
                             % (adjust.data, adjust.gamma))
        return float(adjust.data), float(adjust.gamma)
    return {'emotion': (pair(msg.emotion.valence), pair(msg.emotion.arousal)),
            'mood': (pair(msg.mood.valence), pair(msg.mood.arousal)),
            'sleep': (pair(msg.sleep.wakefulness), pair(msg.sleep.pressure))}
