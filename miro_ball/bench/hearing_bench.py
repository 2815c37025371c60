"""What hearing costs the simulator: MiRo's microphones, side by side.

A world runs as fast as it can, its robots driving in circles, three cases taking turns
(bench.listened): without hearing at all (the world's sound not worked out: the simulator
as it was before it had ears), with hearing but nobody listening (every source sends its
samples, no microphone block is worked out), and with a listener on every robot's
sensors/mics in a process of its own. The simulator's own work: the sound's tick (the
sources, and the blocks heard) and publishing the robots' sensor streams (the blocks are
the only ones listened to; the others cost a look at their subscribers).

Default: the default world, one MiRo. --pitch: the football pitch, three MiRos, and three
sounds beside them (noise, a tone and the radio's tune). --eyes: every robot's eyes
watched in every case.

    python -m miro_ball.bench.hearing_bench [--pitch] [--rounds 7] [--seconds 6] [--eyes]
"""
import sys

from miro_ball.bench.listened import bench_parser, Case, checked, compare, own_difference
from miro_ball.miro.interface import default_robot_name, RobotTopics, TOPIC
from miro_sim_bullet.scene.sounds import bundled_sound, Sound
from miro_sim_bullet.scene.world_file import load_world

BUDGET = {'miro': 0.10, 'football_pitch': 0.20}  # the issue's: of the real-time factor
PITCH_SOUNDS = (Sound('hiss', (0.0, 1.5, 0.3), 'noise', -35.0),
                Sound('whistle', (-1.0, -1.0, 0.3), 'tone', -35.0, frequency=1200.0),
                Sound('radio', (1.5, 0.0, 0.3), 'file', -35.0,
                      file=str(bundled_sound('radio_tune.ogg')), loop=True))


def main(argv=None):
    parser = bench_parser('miro_ball.bench.hearing_bench', __doc__)
    parser.add_argument('--pitch', action='store_true',
                        help='the football pitch, three robots and three sounds')
    args = checked(parser, argv)
    if args is None:
        return 0
    world = 'football_pitch' if args.pitch else 'miro'
    robots = [robot.name or default_robot_name() for robot in load_world(world).robots]
    mics = [(TOPIC['mics'].type, RobotTopics(name).mics, 'MIC_QOS') for name in robots]
    ticks = {}  # the sound's tick as the simulator has it (timed), kept while switched off

    def hearing(on):
        def enter(sim):
            acoustics = sim.sim.acoustics
            ticks.setdefault('on', acoustics.tick)
            acoustics.tick = ticks['on'] if on else (lambda listening: None)
            if args.pitch and on:
                for sound in PITCH_SOUNDS:
                    if sound.name not in acoustics.sounds:
                        acoustics.add_sound(sound)
        return enter

    cases = [Case('without hearing', enter=hearing(False)),
             Case('hearing, nobody listening', enter=hearing(True)),
             Case('sensors/mics listened', mics, hearing(True))]
    eyes = 'every eye watched' if args.eyes else 'no eye watched'
    sounds = f', {len(PITCH_SOUNDS)} sounds' if args.pitch else ''
    print(f'hearing_bench: {world} ({len(robots)} robots{sounds}, {eyes}), {args.rounds} '
          f'rounds of {args.seconds:g} s a case, taking turns', flush=True)

    def timed(sim):
        return [(sim.sim.acoustics, 'tick')] + [(interface, 'publish_streams')
                                                for interface in sim.robots.values()]
    medians, figures = compare('miro_ball.bench.hearing_bench', world, cases,
                               rounds=args.rounds, seconds=args.seconds, eyes=args.eyes,
                               timed=timed, salt=79)
    base = medians[cases[0].label][0]
    print(f'real-time factor (median of {args.rounds}): ' + ', '.join(
        f'{label} {values[0]:.2f} (ratio {values[0] / base:.3f})'
        for label, values in medians.items()))
    cost = 1 - medians[cases[2].label][0] / base
    budget = BUDGET[world]
    print(f'  hearing listened to costs {100 * cost:.1f} % of the real-time factor '
          f'({"within" if cost <= budget else "OVER"} the {100 * budget:g} % budget); the '
          "simulator's own work for it: "
          f'{100 * own_difference(figures, cases[2].label, cases[0].label):.1f} % of its time '
          f'(nobody listening: {100 * own_difference(figures, cases[1].label, cases[0].label):.1f}'
          f' %); the listener got {medians[cases[2].label][3]:.0f} KB per simulated second')
    return 0


if __name__ == '__main__':
    sys.exit(main())
