"""How the grader's sandbox is made (pure): what is hidden, what comes back, as whom; and
where no network namespace can be had, the grader says so."""
import sys
from pathlib import Path

from miro_ball.grading import netns, sandbox

HOME = str(Path('~').expanduser())


def line(tmp_path, uid=1234, hidden=()):
    return sandbox.command_line(['python', 'c.py'], workdir=tmp_path / 'class' / 'alice',
                                scratch=tmp_path / 'scratch', env={'HOME': 'x'}, uid=uid,
                                hidden=hidden)


def steps(args):
    """(option, path) of the mounts, in order."""
    return [(a, args[i + 1]) for i, a in enumerate(args) if a in ('--tmpfs', '--ro-bind',
                                                                  '--bind', '--dir')]


def test_homes_are_hidden_before_the_python_and_the_project_come_back(tmp_path):
    mounts = steps(line(tmp_path))
    assert mounts.index(('--tmpfs', HOME)) < mounts.index(('--ro-bind', sys.base_prefix))
    assert ('--tmpfs', '/tmp') in mounts and ('--ro-bind', '/') in mounts


def test_a_class_folder_inside_the_project_is_hidden_again_but_for_the_students_own(
        tmp_path, monkeypatch):
    project = str(tmp_path / 'project')
    class_dir = Path(project) / 'students'
    (class_dir / 'bob').mkdir(parents=True)
    monkeypatch.setattr(sandbox, 'project_root', lambda: Path(project))
    args = sandbox.command_line(['run'], workdir=class_dir / 'bob', scratch=tmp_path,
                                env={}, uid=7, hidden=[class_dir])
    mounts = steps(args)
    project_at = mounts.index(('--ro-bind', project))
    hidden_at = mounts.index(('--tmpfs', str(class_dir)))
    assert project_at < hidden_at < mounts.index(('--ro-bind', str(class_dir / 'bob')))


def test_as_root_it_runs_as_its_own_user_else_in_a_user_namespace(tmp_path):
    as_root = line(tmp_path, uid=1234)
    assert as_root[as_root.index('--') + 1:][:2] == ['setpriv', '--reuid=1234']
    assert '--unshare-user' not in as_root
    userns = line(tmp_path, uid=None)
    assert '--unshare-user' in userns and userns[-2:] == ['python', 'c.py']
    assert {'--unshare-pid', '--die-with-parent', '--new-session', '--clearenv'} <= set(userns)


def test_without_a_network_namespace_the_report_says_what_keeps_episodes_apart(monkeypatch):
    monkeypatch.setattr(netns, '_prefix', lambda: ['sh', '-c', 'echo no way >&2; exit 1', '--'])
    prefix, words = netns.namespace_prefix.__wrapped__()
    assert prefix == [] and 'no way' in words and 'ROS domains only' in words


def test_python_commands_can_be_started_ahead_others_not():
    from miro_ball.grading.warm_start import python_args

    assert python_args(['python', '-m', 'miro_ball', '--ros-args']) == ['-m', 'miro_ball',
                                                                         '--ros-args']
    assert python_args([sys.executable, 'controller.py', 'x']) == ['controller.py', 'x']
    assert python_args(['python3', '-c', 'print(1)']) == ['-c', 'print(1)']
    for other in (['./run'], ['python', '-u', 'c.py'], ['/usr/bin/python2', 'c.py'],
                  ['python'], ['sh', 'c.py']):
        assert python_args(other) is None


def test_a_command_started_ahead_runs_only_when_told_as_python_would(tmp_path):
    import subprocess

    script = tmp_path / 'student.py'
    script.write_text('import os, sys\nhere = os.path.dirname(os.path.abspath(sys.argv[0]))\n'
                      'print("ran", sys.argv, sys.path[0] == here, __name__, flush=True)\n'
                      'sys.exit(3)\n')
    waiting = subprocess.Popen([sys.executable, '-m', 'miro_ball.grading.warm_start', '--',
                                'python', str(script), 'a'], stdin=subprocess.PIPE,
                               stdout=subprocess.PIPE, text=True)
    out, _ = waiting.communicate('go\n', timeout=60)
    assert waiting.returncode == 3
    assert out.startswith(f"ran ['{script}', 'a'] True __main__")
    never = subprocess.run([sys.executable, '-m', 'miro_ball.grading.warm_start', '--',
                            'python', str(script)], stdin=subprocess.DEVNULL,
                           capture_output=True, text=True, timeout=60)
    assert never.returncode == 0 and 'ran' not in never.stdout  # no go: it never ran
