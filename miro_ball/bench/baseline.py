"""An earlier commit of this project, checked out beside it, to benchmark side by side.

The simulator benchmark runs each case with this tree and with the commit in turns, so
that both see the same load on a shared machine. The commit gets a git worktree of its
own (kept under the system's temporary directory for the next run) and runs on this
tree's virtual environment with its own packages and worlds first on the path.

``landed`` names the previous landing: the commit in .ci/landed, which the first commit of
each round of work sets to the main it started from.
"""
import os
import subprocess
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
# Where the simulator benchmark lived: it moved from lab/ to bench/.
BENCH_MODULES = ('miro_ball/bench/sim_bench.py', 'miro_ball/lab/sim_bench.py')
LANDED = ROOT / '.ci' / 'landed'  # its first word: the previous landing's commit


class BaselineError(RuntimeError):
    """The commit can not be checked out or has no simulator benchmark; one line."""


def landed():
    """The previous landing's commit, as .ci/landed says."""
    try:
        words = LANDED.read_text().split()
    except OSError as exc:
        raise BaselineError(f'{LANDED} can not be read ({exc.strerror})') from None
    except UnicodeDecodeError:
        raise BaselineError(f'{LANDED} is not text') from None
    if not words:
        raise BaselineError(f'{LANDED} names no commit')
    return words[0]


def checkout(ref):
    """(worktree path, the commit's sim_bench module name) for git ``ref`` ('landed': the
    previous landing)."""
    if ref == 'landed':
        ref = landed()
    try:
        commit = subprocess.run(['git', '-C', str(ROOT), 'rev-parse', '--verify',
                                 f'{ref}^{{commit}}'], capture_output=True, text=True,
                                check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        raise BaselineError(f'{ref!r} is no commit of {ROOT}') from None
    tree = Path(tempfile.gettempdir()) / f'miro_ball_baseline_{commit[:12]}'
    if not (tree / 'setup.py').exists():
        done = subprocess.run(['git', '-C', str(ROOT), 'worktree', 'add', '--force',
                               '--detach', str(tree), commit], capture_output=True, text=True)
        if done.returncode:
            raise BaselineError(f'git worktree add {tree} failed: {done.stderr.strip()}')
    # The worlds are the package miro_sim_bullet.worlds (setup.py maps it to worlds/): a
    # link makes the commit's own worlds the ones its simulator finds first.
    link = tree / 'miro_sim_bullet' / 'worlds'
    if not link.exists():
        link.symlink_to(tree / 'worlds')
    for module in BENCH_MODULES:
        if (tree / module).exists():
            return tree, module[:-3].replace('/', '.')
    raise BaselineError(f'{ref} has no simulator benchmark')


def environment(tree, env):
    """env with the commit's packages ahead of this tree's on the path."""
    env = dict(env)
    env['PYTHONPATH'] = os.pathsep.join(filter(None, [str(tree), env.get('PYTHONPATH')]))
    return env
