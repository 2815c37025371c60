"""``$(...)`` in a launch file's values: the substitutions our launch files use, as ROS 2's
launch performs them. ``$(var NAME)``: an argument's or a let's value; ``$(find-pkg-share
PKG)``: the package's share folder; ``$(env NAME)`` or ``$(env NAME DEFAULT)``: an
environment variable. Any other is refused in one line naming it."""
import shlex

from miro_ball.launch import LaunchError

SUPPORTED = ('var', 'find-pkg-share', 'env')
MAX_CHARS = 10_000  # of a value once substituted: a let that doubles itself grows 2^n


def substitute(text, scope):
    """text with every $(...) replaced. scope: its ``file``, ``configs`` (name -> value),
    ``share`` (package -> folder) and ``environ``."""
    done, rest = [], text
    while (start := rest.find('$(')) >= 0:
        end = rest.find(')', start)
        inner = rest[start + 2:end]
        if end < 0 or '$(' in inner:
            what = 'an unclosed $(' if end < 0 else 'a $(...) inside another'
            raise LaunchError(f'{scope.file}: {what} in {text!r} (not supported)')
        done += [rest[:start], _one(inner, scope)]
        rest = rest[end + 1:]
    value = ''.join(done) + rest
    if len(value) > MAX_CHARS:
        raise LaunchError(f'{scope.file}: {text[:40]!r} is over {MAX_CHARS} characters once '
                          'substituted')
    return value


def _one(inner, scope):
    try:
        words = shlex.split(inner)
    except ValueError as err:
        raise LaunchError(f'{scope.file}: $({inner}): {err}') from None
    kind, args = (words[0], words[1:]) if words else ('', [])
    where = f'{scope.file}: $({inner})'
    if kind not in SUPPORTED:
        raise LaunchError(f'{where} is not supported by python -m miro_ball.launch (it takes '
                          f'{", ".join(f"$({name} ...)" for name in SUPPORTED)})')
    if kind == 'env' and len(args) in (1, 2):
        if args[0] in scope.environ or len(args) == 2:
            return scope.environ.get(args[0], args[-1])
        raise LaunchError(f'{where}: the environment has no {args[0]} (give a default: '
                          f'$(env {args[0]} DEFAULT))')
    if len(args) != 1:
        raise LaunchError(f'{where} takes one name')
    if kind == 'var':
        if args[0] not in scope.configs:
            raise LaunchError(f'{where}: no arg or let named {args[0]!r} comes before it')
        return scope.configs[args[0]]
    return str(scope.share(args[0]))


def truth(value, where):
    """An if/unless condition's value; LaunchError if it is neither true nor false."""
    lowered = value.strip().lower()
    if lowered in ('true', '1'):
        return True
    if lowered in ('false', '0'):
        return False
    raise LaunchError(f'{where}: a condition is true or false (or 1, 0), got {value!r}')
