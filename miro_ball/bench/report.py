"""BENCHMARKS.md: each benchmark owns a marked section of it and rewrites only that."""
import os
import platform
from pathlib import Path


def machine():
    """One line about the machine the figures come from."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path('/proc/cpuinfo').read_text().splitlines():
            if line.startswith('model name'):
                cpu = line.split(':', 1)[1].strip()
                break
    except OSError:
        pass
    return (f'{platform.system()} {platform.release()}, {os.cpu_count()} cores ({cpu}), '
            f'Python {platform.python_version()}')


def load_average():
    """The machine's load average over 1, 5 and 15 minutes, as one line."""
    return ', '.join(f'{v:.2f}' for v in os.getloadavg())


def markers(name):
    return (f'<!-- {name}: written by python -m miro_ball.bench.{name} -->',
            f'<!-- end of {name} -->')


def write_section(path, name, text):
    """Put text between the markers of section ``name`` of path, replacing what was there
    (or adding the section at the end); the rest of the file stays as it is. A start marker
    is known by its name alone, so one naming an older module still counts."""
    path = Path(path)
    start, end = markers(name)
    opening = start.split(':', 1)[0] + ':'
    old = path.read_text() if path.exists() else ''
    section = f'{start}\n{text}\n{end}\n'
    if opening in old and end in old:
        head, _, rest = old.partition(opening)
        _, _, tail = rest.partition(end + '\n')
        path.write_text(head + section + tail)
    else:
        path.write_text(old + ('\n' if old and not old.endswith('\n\n') else '') + section)
