"""Grading on a Ray cluster of two nodes on this machine (Ray's own multi-node test helper):
the same table as a local run, and a node lost mid-run loses no episode and counts none
twice."""
import json
import subprocess
import sys

import pytest
from ray.cluster_utils import Cluster

from test_grade_class import make_class

PY = sys.executable
DETERMINISTIC = ['fake_sensors', 'teleport_ball']  # their tables do not depend on timing


@pytest.fixture
def cluster():
    made = Cluster(initialize_head=True, head_node_args={'num_cpus': 1})
    second = made.add_node(num_cpus=1)
    made.wait_for_nodes()
    yield made, second
    made.shutdown()


def grade_args(class_dir, out, *args):
    return [PY, '-m', 'miro_ball.grade', '--class', str(class_dir), '--out', str(out),
            '--grace', '2', '--no-video', *args]


def report_of(out):
    [report] = out.iterdir()
    return report


def test_a_ray_cluster_grades_as_this_machine_does(cluster, tmp_path):
    made, _ = cluster
    class_dir = make_class(tmp_path / 'students', DETERMINISTIC)
    tables = {}
    for where, extra in (('local', []), ('ray', ['--ray', made.address])):
        done = subprocess.run(grade_args(class_dir, tmp_path / where, '--count', '2',
                                         '--limit', '2', '--seed', '3', *extra),
                              capture_output=True, text=True, timeout=300)
        assert done.returncode == 0 and 'Traceback' not in done.stderr, done.stderr
        tables[where] = (report_of(tmp_path / where) / 'results.csv').read_bytes()
    assert tables['local'] == tables['ray']


def test_a_node_lost_mid_run_loses_no_episode(cluster, tmp_path):
    made, second = cluster
    class_dir = make_class(tmp_path / 'students', ['idle'])
    # Each episode runs to its limit, a node's two tasks one after the other.
    grading = subprocess.Popen(grade_args(class_dir, tmp_path / 'out', '--count', '4',
                                          '--limit', '4', '--command-wait', '0',
                                          '--ray', made.address),
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lines = []
    for line in grading.stdout:
        lines.append(line)
        if line.lstrip().startswith('[1/4]'):
            made.remove_node(second)  # while the second node runs an episode
            break
    out, err = grading.communicate(timeout=300)
    assert grading.returncode == 0 and 'Traceback' not in err, err
    episodes = json.loads((report_of(tmp_path / 'out') / 'results.json').read_text())[
        'episodes']
    assert sorted(e['index'] for e in episodes) == [1, 2, 3, 4]
    assert all(e['ended'] == 'limit' and e['sim_time'] >= 4 for e in episodes)
    # The second node ran one episode at most: the one it ran when lost went to the head.
    head = made.head_node.node_id
    assert sum(e['ran_on'] == head for e in episodes) >= 3
    assert sum(line.lstrip().startswith('[') for line in lines + out.splitlines()) == 4
