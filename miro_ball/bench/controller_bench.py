"""Controller benchmark: detection cost per frame and the node's image-to-command latency.

    python -m miro_ball.bench.controller_bench [--frames N] [--latency N] [--cv-threads N]

Detection runs on synthetic frames (shaded balls on a grey floor, see synthetic.py).
The latency part runs the node in-process on wall time, publishes a JPEG to one eye
and spins until the frame has been through the detector and until the next twist
comes back; the latter includes the wait for the next control tick.
"""
import argparse
import statistics
import time

import cv2
import numpy as np

from miro_ball.miro.constants import FRAME_SIZES
from miro_ball.controller.detection import BallDetector
from miro_ball.common.isolation import limit_discovery, private_domain
from miro_ball.miro.interface import RobotTopics
from miro_ball.bench.synthetic import Disc, jpeg, render

BENCH_ROBOT = 'miro_bench'  # a name no real simulator or robot answers to
POOL = 16  # distinct frames per case; rendering is slower than detecting


def scenes(width, height, with_ball, seed=0):
    rng = np.random.default_rng(seed)
    frames = []
    for i in range(POOL):
        discs = []
        if with_ball:
            r = rng.uniform(0.015, 0.07) * width
            discs.append(Disc(rng.uniform(r, width - r), rng.uniform(r, height - r), r))
        frames.append(render(width, height, discs, seed=seed + i))
    return frames


def percentiles(samples_s):
    ms = sorted(1e3 * s for s in samples_s)
    return statistics.median(ms), ms[min(len(ms) - 1, int(0.9 * len(ms)))]


def time_each(fn, inputs, count):
    samples = []
    for i in range(count):
        item = inputs[i % len(inputs)]
        start = time.perf_counter()
        fn(item)
        samples.append(time.perf_counter() - start)
    return samples


def bench_detection(count):
    detector = BallDetector()
    print('detection, ms per frame over %d frames (median / p90), %d OpenCV threads'
          % (count, cv2.getNumThreads()))
    for width, height in FRAME_SIZES:
        for with_ball in (True, False):
            frames = scenes(width, height, with_ball)
            found = sum(detector.detect(f) is not None for f in frames)
            median, p90 = percentiles(time_each(detector.detect, frames, count))
            print('  %4dx%-4d %-8s %6.2f / %6.2f   (found in %d of %d frames)'
                  % (width, height, 'ball' if with_ball else 'no ball', median, p90,
                     found, len(frames)))
    data = [np.frombuffer(jpeg(f), np.uint8) for f in scenes(640, 360, True)]
    median, p90 = percentiles(time_each(lambda d: cv2.imdecode(d, cv2.IMREAD_COLOR), data, count))
    print('  640x360   JPEG decode (not in the above) %.2f / %.2f' % (median, p90))


def bench_latency(count):
    import rclpy
    from rclpy.context import Context
    from geometry_msgs.msg import TwistStamped
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from sensor_msgs.msg import CompressedImage

    from miro_ball.controller.host import ControllerHost
    from miro_ball.controller.kick_blue_ball import KICK_BLUE_BALL

    # A private domain and robot name: never talk to a real simulator or robot.
    limit_discovery()
    context = Context()
    rclpy.init(context=context, domain_id=private_domain(salt=75))
    node = ControllerHost(KICK_BLUE_BALL, context=context, robot=BENCH_ROBOT, parameter_overrides=[
        Parameter('head_hold_s', value=0.0)])
    probe = rclpy.create_node('bench_probe', context=context)
    twists = []
    topics = RobotTopics(BENCH_ROBOT)
    probe.create_subscription(TwistStamped, topics.cmd_vel,
                              lambda msg: twists.append(time.perf_counter()), 10)
    pub = probe.create_publisher(CompressedImage, topics.eye_compressed('caml'), 2)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    executor.add_node(probe)

    def spin_until(predicate, limit_s=2.0):
        deadline = time.perf_counter() + limit_s
        while not predicate():
            if time.perf_counter() > deadline:
                raise RuntimeError('no answer from the node within %g s' % limit_s)
            executor.spin_once(timeout_sec=0.001)

    frames = [jpeg(f) for f in scenes(640, 360, True)]
    phases = np.random.default_rng(0).uniform(0.0, node.config.tick, count)
    try:
        spin_until(lambda: pub.get_subscription_count() > 0 and twists, 5.0)
        detected, commanded = [], []
        for i in range(count):
            # Publish at a random point of the tick, as a camera would.
            ready = time.perf_counter() + phases[i]
            spin_until(lambda: time.perf_counter() >= ready)
            done, sent = node.frames_processed, len(twists)
            start = time.perf_counter()
            pub.publish(CompressedImage(format='jpeg', data=frames[i % len(frames)]))
            spin_until(lambda: node.frames_processed > done)
            detected.append(time.perf_counter() - start)
            spin_until(lambda: len(twists) > sent and twists[-1] > start + detected[-1])
            commanded.append(twists[-1] - start)
    finally:
        executor.shutdown()
        node.destroy_node()
        probe.destroy_node()
        rclpy.try_shutdown(context=context)
    print('node latency over %d JPEG frames, 640x360, ms (median / p90)' % count)
    print('  image published -> detection done    %6.2f / %6.2f' % percentiles(detected))
    print('  image published -> next twist out    %6.2f / %6.2f   (includes waiting for the'
          ' next %g s tick)' % (percentiles(commanded) + (node.config.tick,)))


def main(argv=None):
    parser = argparse.ArgumentParser(prog='python -m miro_ball.bench.controller_bench',
                                     description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--frames', type=int, default=300, help='detections per case')
    parser.add_argument('--latency', type=int, default=100, help='frames for the node latency')
    parser.add_argument('--cv-threads', type=int, default=1,
                        help='OpenCV threads (the kick_blue_ball command uses 1)')
    options = parser.parse_args(argv)
    cv2.setNumThreads(options.cv_threads)
    bench_detection(options.frames)
    if options.latency > 0:
        bench_latency(options.latency)


if __name__ == '__main__':
    main()
