"""python -m miro_ball.bench.control_bench: how long the standard simulator services take.

The simulator runs as a process (paused, on a ROS domain of its own) and a client calls each
service of simulation_interfaces, as any tool would: wall milliseconds from the call to the
answer, the median of --repeats calls, for the default world and the football pitch. Besides
the standard's step_simulation, the older ~/step alias is timed in turns with it, the same
number of steps, so that the two are compared side by side.
"""
import argparse
import statistics
import subprocess
import sys
import time
from pathlib import Path

from miro_ball.bench.report import machine, write_section
from miro_ball.common.isolation import isolated_env, private_domain

SECTION = 'control_bench'


def _client():
    """(node, executor, context): an rclpy client on this process's domain."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor

    context = rclpy.Context()
    rclpy.init(context=context)
    node = rclpy.create_node('control_bench', context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    return node, executor, context


class Caller:
    """Calls /miro_sim/<service> by type and times it."""

    def __init__(self, node, executor):
        self.node, self.executor, self.clients = node, executor, {}

    def __call__(self, kind, name=None, **fields):
        name = name or ''.join('_' + c.lower() if c.isupper() else c
                               for c in kind.__name__).lstrip('_')
        client = self.clients.get(name)
        if client is None:
            client = self.clients[name] = self.node.create_client(kind, f'/miro_sim/{name}')
            if not client.wait_for_service(timeout_sec=60):
                raise SystemExit(f'control_bench: no /miro_sim/{name} after 60 s')
        started = time.perf_counter()
        future = client.call_async(kind.Request(**fields))
        self.executor.spin_until_future_complete(future, timeout_sec=120)
        if not future.done():
            raise SystemExit(f'control_bench: /miro_sim/{name} did not answer')
        return (time.perf_counter() - started) * 1000, future.result()


def _simulator(world, env):
    return subprocess.Popen([sys.executable, '-m', 'miro_sim_bullet', '--world', world,
                             '--ros-args', '-p', 'paused:=true', '-p', 'peer_check_s:=0'],
                            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def measure(world, repeats, call):
    """[(what, median ms)] of each service on a world the simulator has just loaded."""
    from geometry_msgs.msg import PoseStamped
    from simulation_interfaces import srv
    from simulation_interfaces.msg import EntityFilters
    from std_srvs.srv import Trigger

    def median(kind, name=None, after=None, **fields):
        times = []
        for _ in range(repeats):
            ms, response = call(kind, name, **fields)
            times.append(ms)
            if after is not None:
                after(response)
        return statistics.median(times)

    entities = call(srv.GetEntities, filters=EntityFilters())[1].entities
    where = PoseStamped()
    where.pose.position.x = where.pose.position.y = 0.3
    rows = [
        ('get_simulation_state (a round trip)', median(srv.GetSimulationState)),
        ('get_entities_states, every entity',
         median(srv.GetEntitiesStates, filters=EntityFilters())),
        ('get_entity_state of the ball', median(srv.GetEntityState, entity='ball')),
    ]
    # The standard's step and the older alias in turns: 10 steps (a 20 ms platform tick).
    standard, alias = [], []
    for _ in range(repeats):
        standard.append(call(srv.StepSimulation, steps=10)[0])
        alias.append(call(Trigger, 'step')[0])
    rows += [('step_simulation, 10 steps', statistics.median(standard)),
             ('~/step (the older alias), 10 steps', statistics.median(alias)),
             ('step_simulation, 500 steps (1 s)', median(srv.StepSimulation, steps=500))]
    spawned = []
    rows.append(('spawn_entity MiRo-E (its topics made too)', median(
        srv.SpawnEntity, uri='package://miro_ball/robots/miro.urdf', allow_renaming=True,
        initial_pose=where, after=lambda r: spawned.append(r.entity_name))))
    rows.append(('delete_entity of that MiRo', _each(call, srv.DeleteEntity, spawned)))
    spawned.clear()
    rows.append(('spawn_entity a box', median(
        srv.SpawnEntity, uri='package://miro_ball/worlds/models/box.toml', allow_renaming=True,
        initial_pose=where, after=lambda r: spawned.append(r.entity_name))))
    rows.append(('delete_entity of that box', _each(call, srv.DeleteEntity, spawned)))
    rows.append(('reset_simulation (all)', median(srv.ResetSimulation)))
    rows.append((f'load_world {world} again', median(srv.LoadWorld, uri=world_uri(world))))
    return rows, len(entities)


def _each(call, kind, names):
    return statistics.median(call(kind, entity=name)[0] for name in names)


def world_uri(name):
    return f'package://miro_ball/worlds/{name}.toml'


def main(argv=None):
    parser = argparse.ArgumentParser(prog='python -m miro_ball.bench.control_bench',
                                     description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--repeats', type=int, default=9, help='calls a median is of')
    parser.add_argument('--worlds', default='miro,football_pitch',
                        help='bundled worlds to time, comma-separated')
    parser.add_argument('--output', type=Path, help='write the table into this file '
                        '(BENCHMARKS.md) between its control_bench markers')
    args = parser.parse_args(argv)
    if not 1 <= args.repeats <= 1000:
        parser.error('--repeats must be 1 to 1000')
    worlds = [w for w in args.worlds.split(',') if w]
    import os
    os.environ.update(isolated_env(private_domain()))
    node, executor, context = _client()
    table, counts = {}, {}
    try:
        for world in worlds:
            sim = _simulator(world, dict(os.environ))
            try:
                print(f'[control_bench] {world}: timing ...', flush=True)
                table[world], counts[world] = measure(world, args.repeats,
                                                      Caller(node, executor))
            finally:
                sim.terminate()
                sim.wait(timeout=30)
    finally:
        import rclpy
        node.destroy_node()
        rclpy.shutdown(context=context)
    header = '| service | ' + ' | '.join(f'{w}, {counts[w]} entities (ms)'
                                         for w in worlds) + ' |'
    lines = [header, '|' + '---|' * (len(worlds) + 1)]
    for index, (what, _) in enumerate(table[worlds[0]]):
        lines.append(f'| {what} | ' + ' | '.join(
            f'{table[w][index][1]:.1f}' for w in worlds) + ' |')
    text = (f'Wall ms from the call to the answer, median of {args.repeats}, a client in '
            f'another process; {machine()}; {time.strftime("%Y-%m-%d %H:%M")}.\n\n'
            + '\n'.join(lines))
    print(text)
    if args.output:
        write_section(args.output, SECTION, text)
    return 0


if __name__ == '__main__':
    sys.exit(main())
