"""The scenario benchmark plays the same episodes whatever the number of worker processes."""
from miro_ball.bench.scenario_bench import run, table
from miro_ball.run.placements import placements


def test_outcomes_do_not_depend_on_the_number_of_jobs():
    chosen = placements(2, seed=5)
    lines = []
    alone = run(['improved'], chosen, 5, 20.0, 'auto', jobs=1, report=lines.append)
    shared = run(['improved'], chosen, 5, 20.0, 'auto', jobs=2, report=lines.append)

    def key(results):
        return [(o.kicked, o.fell, o.time_to_kick) for o in results['improved']]
    assert key(alone) == key(shared)
    assert len(lines) == 4 and any(o.kicked for o in alone['improved'])
    assert '| improved |' in table(alone, 2)
