"""What MiRo's body on ROS costs the simulator: /tf and joint_states, side by side.

The football pitch (three MiRos, driving in circles) runs as fast as it can (real-time
factor 0) in this process, rounds taking turns: with nobody listening to the body, and
with a listener (as Foxglove or RViz would be) on /tf and every robot's joint_states. The
listener takes the messages' bytes only (no deserialising), so what is measured is the
simulator's side: building, serialising and sending. No eye is watched (the worst case:
the body's share of a tick is largest). Figures: the medians of the rounds' real-time
factors and their ratio.

    python -m miro_ball.bench.body_bench [--rounds 5] [--seconds 6]
"""
import argparse
import statistics
import sys
import time

WORLD = 'football_pitch'
TARGET_COST = 0.03  # the budget: at most 3 % of the real-time factor
WARMUP_S = 1.0


def main(argv=None):
    parser = argparse.ArgumentParser(prog='python -m miro_ball.bench.body_bench',
                                     description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--rounds', type=int, default=5, help='rounds of each case (5)')
    parser.add_argument('--seconds', type=float, default=6.0, help='wall seconds a round (6)')
    args = parser.parse_args(argv)
    if not 1 <= args.rounds <= 100 or not 1 <= args.seconds <= 600:
        parser.error('--rounds must be in [1, 100] and --seconds in [1, 600]')

    import rclpy
    from geometry_msgs.msg import TwistStamped
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from sensor_msgs.msg import JointState

    from miro_ball.common.isolation import limit_discovery, private_domain
    from miro_ball.common.messages import message_class
    from miro_ball.common.qos import profile
    from miro_ball.miro.interface import RobotTopics, SENSOR_QOS, TF, TF_QOS, TF_TYPE, TOPIC
    from miro_sim_bullet.ros.node import SimNode

    limit_discovery()
    context = Context()
    rclpy.init(context=context, domain_id=private_domain(salt=73))
    executor = SingleThreadedExecutor(context=context)
    sim = SimNode(context=context, parameter_overrides=[
        Parameter('world', value=WORLD), Parameter('real_time_factor', value=0.0),
        Parameter('renderer', value='tiny'), Parameter('eye_workers', value=False)])
    listener = rclpy.create_node('body_listener', context=context)
    executor.add_node(sim)
    executor.add_node(listener)
    robots = list(sim.robots)
    received = [0]

    def count(data):
        received[0] += len(data)

    def listen():
        return [listener.create_subscription(message_class(TF_TYPE), TF, count,
                                             profile(TF_QOS), raw=True)] + [
            listener.create_subscription(JointState,
                                         RobotTopics(name).topic(TOPIC['joint_states'].name),
                                         count, profile(SENSOR_QOS), raw=True)
            for name in robots]

    def run(seconds):
        start_wall, start_sim = time.monotonic(), sim.sim.time
        while time.monotonic() - start_wall < seconds:
            for robot in sim.sim.robots.values():
                robot.set_cmd_vel(0.2, 0.8)
            executor.spin_once(timeout_sec=0.05)
        return (sim.sim.time - start_sim) / (time.monotonic() - start_wall)

    rtf = {'nobody listening': [], '/tf + joint_states': []}
    kb_s = []
    print(f'body_bench: {WORLD} ({len(robots)} robots), {args.rounds} rounds of '
          f'{args.seconds:g} s a case, taking turns', flush=True)
    try:
        for k in range(args.rounds):
            run(WARMUP_S)
            rtf['nobody listening'].append(run(args.seconds))
            subs = listen()
            run(WARMUP_S)
            received[0], sim_start = 0, sim.sim.time
            rtf['/tf + joint_states'].append(run(args.seconds))
            kb_s.append(received[0] / 1000 / (sim.sim.time - sim_start))
            for sub in subs:
                listener.destroy_subscription(sub)
            print(f'  round {k + 1}: ' + ', '.join(f'{label} {values[-1]:.2f}'
                                                   for label, values in rtf.items()), flush=True)
    finally:
        executor.shutdown(timeout_sec=1.0)
        sim.destroy_node()
        listener.destroy_node()
        rclpy.try_shutdown(context=context)
    without, with_body = (statistics.median(v) for v in rtf.values())
    cost = 1 - with_body / without
    verdict = 'within' if cost <= TARGET_COST else 'OVER'
    print(f'real-time factor (median of {args.rounds}): nobody listening {without:.2f}, '
          f'/tf + joint_states listened to {with_body:.2f}: ratio {with_body / without:.3f}, '
          f'a cost of {100 * cost:.1f} % ({verdict} the {100 * TARGET_COST:g} % budget); '
          f'{statistics.median(kb_s):.0f} KB per simulated second')
    return 0


if __name__ == '__main__':
    sys.exit(main())
