"""A class's grades, written where a teacher looks: out/grade/<timestamp>/ holds index.html (a
table per student, each failed episode's video one click away), results.csv (one row per
student, for a spreadsheet) and results.json (everything).

Plain Python, no ROS. The episodes are the report's dicts (episode_facts.complete). The
files depend only on what is given: the same meta and episodes give byte-identical files, so
a re-run with the same seed gives the same table (wall times live only in meta and in each
episode's wall_time). Students choose their folder names and their output, so every
string from them is HTML-escaped and control characters are replaced.
"""
import csv
import html
import io
import json
import re
import statistics
from pathlib import Path
from urllib.parse import quote

from miro_ball.grading.scores import placement_text

CONTROL = re.compile(r'[\x00-\x08\x0b-\x1f\x7f\ud800-\udfff]')
FIELDS = ('student', 'score', 'episodes', 'kicked', 'median_time_to_kick', 'fell', 'cheated',
          'crashed')


def report_folder(root, now):
    """root/YYYYmmdd-HHMMSS of datetime now, created here so that two graders started in the
    same second never share one: the second gets -2, then -3..."""
    stem = now.strftime('%Y%m%d-%H%M%S')
    Path(root).mkdir(parents=True, exist_ok=True)
    for n in range(1, 10000):
        folder = Path(root) / (stem if n == 1 else f'{stem}-{n}')
        try:
            folder.mkdir()
            return folder
        except FileExistsError:
            continue
    raise ValueError(f'{root}: no free report folder for {stem}')


def success(episode):
    """Won: a cheated episode never counts, whatever else it says."""
    return bool(episode['success']) and not episode.get('cheated')


def mark(episode):
    """The short word for one episode in the table: 'kick 4.2', 'cheated', 'fell', 'crashed',
    'no'."""
    if episode.get('cheated'):
        return 'cheated'
    if success(episode):
        return 'kick' + _number(episode['time_to_kick'], ' {:.1f}')
    if episode['fell']:
        return 'fell'
    if episode['crashed']:
        return 'crashed'
    return 'no'


def _by_student(episodes):
    found = {}
    for episode in sorted(episodes, key=lambda e: (e['student'], e['index'])):
        found.setdefault(episode['student'], {})[episode['index']] = episode
    return found


def summaries(students, episodes, count):
    """One dict per student (the listed ones and any with episodes), sorted by name: score,
    kicked (not cheated), median time to kick over won episodes (None when none), fell,
    cheated, the reasons, crashed, and marks, one per placement 1..count ('not run' when
    missing)."""
    by_student = _by_student(episodes)
    found = []
    for name in sorted(set(students) | set(by_student)):
        mine = by_student.get(name, {})
        ran = list(mine.values())
        times = [e['time_to_kick'] for e in ran if success(e) and e['time_to_kick'] is not None]
        found.append({
            'student': name, 'score': sum(success(e) for e in ran), 'episodes': count,
            'ran': len(ran), 'kicked': sum(bool(e['kicked'] and not e.get('cheated'))
                                           for e in ran),
            'median_time_to_kick': statistics.median(times) if times else None,
            'fell': sum(bool(e['fell']) for e in ran),
            'cheated': sum(bool(e.get('cheated')) for e in ran),
            'cheated_reasons': list(dict.fromkeys(e['cheated'] for e in ran if e.get('cheated'))),
            'crashed': sum(bool(e['crashed']) for e in ran),
            'why': _same_crash(ran),
            'marks': [mark(mine[i]) if i in mine else 'not run' for i in range(1, count + 1)]})
    return found


def _same_crash(ran):
    """The last line its command printed when every episode of a student crashed with the
    same one (a path the student's run can not reach, an import error), else None: a
    teacher reads why in one line instead of opening each episode's log."""
    last = {(e.get('output_tail') or [''])[-1].strip() for e in ran if e['crashed']}
    if ran and all(e['crashed'] for e in ran) and len(last) == 1 and '' not in last:
        return last.pop()
    return None


def _number(value, form, missing=''):
    return missing if value is None else form.format(value)


def _who(name):
    return name or '(the command)'


def _median(summary):
    return _number(summary['median_time_to_kick'], '{:.1f} s', '-')


def _cheated(summary):
    reasons = '; '.join(summary['cheated_reasons'])
    return f'{summary["cheated"]}' + (f' ({reasons})' if reasons else '')


def summary_line(summary, width=11):
    """alice       3/5 kicked, median 4.2 s, fell 0, cheated 1 (published on /clock), crashed 0
    """
    why = summary.get('why')
    return (f'{_who(summary["student"]):<{width}} {summary["score"]}/{summary["episodes"]} '
            f'kicked, median {_median(summary)}, fell {summary["fell"]}, cheated '
            f'{_cheated(summary)}, crashed {summary["crashed"]}'
            + (f' (every episode: {why})' if why else ''))


def write_report(folder, meta, students, episodes):
    """results.json, results.csv and index.html in folder (created if missing); the paths."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    ordered = sorted(episodes, key=lambda e: (e['student'], e['index']))
    count = max([meta['count']] + [e['index'] for e in ordered])
    table = summaries(students, ordered, count)
    files = {'results.json': json.dumps({'meta': meta, 'students': table, 'episodes': ordered},
                                        indent=1, sort_keys=True) + '\n',
             'results.csv': _csv(table, count),
             'index.html': _html(meta, table, ordered)}
    for name, text in files.items():
        (folder / name).write_text(text, encoding='utf-8', errors='replace')
    return [folder / name for name in files]


def _csv(table, count):
    out = io.StringIO()
    writer = csv.writer(out, lineterminator='\n')
    writer.writerow(FIELDS + tuple(f'ep{i}' for i in range(1, count + 1)))
    for s in table:
        row = dict(s, median_time_to_kick=_number(s['median_time_to_kick'], '{:.1f}'))
        writer.writerow([row[f] for f in FIELDS] + s['marks'])
    return out.getvalue()


def _e(value):
    """Text safe inside HTML, attributes included."""
    return html.escape(CONTROL.sub('\ufffd', str(value)), quote=True)


def _anchor(name):
    return 'student-' + quote(name, safe='', errors='replace')


STYLE = ('body{font-family:sans-serif;margin:1.5em;color:#222}'
         'table{border-collapse:collapse;margin:.5em 0 1.5em}'
         'th,td{border:1px solid #bbb;padding:.25em .6em;text-align:left;vertical-align:top}'
         'th{background:#eee}td.num{text-align:right}.won{background:#e6f4e6}'
         '.cheated{background:#f8d7d7}pre{margin:.3em 0;max-height:20em;overflow:auto;'
         'background:#f6f6f6;padding:.4em;white-space:pre-wrap}')
META = (('seed', 'seed'), ('count', 'placements'), ('world', 'world'),
        ('limit_s', 'limit (simulated s)'), ('real_time_factor', 'real-time factor'),
        ('started', 'started'), ('wall_s', 'wall time (s)'))


def _html(meta, table, episodes):
    title = 'MiRo grades' + _number(meta.get('started'), ', {}')
    rows = ''.join(f'<tr><th>{label}</th><td>{_e(meta[key])}</td></tr>'
                   for key, label in META if meta.get(key) is not None)
    parts = ['<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">',
             f'<title>{_e(title)}</title><style>{STYLE}</style></head><body>',
             f'<h1>{_e(title)}</h1><table>{rows}</table>',
             f'<p class="isolation">{_e(meta.get("isolation", ""))}</p>',
             '<h2>Students</h2><table><tr><th>student</th><th>score</th>'
             '<th>median time to kick</th><th>fell</th><th>cheated</th><th>crashed</th></tr>']
    for s in table:
        parts.append(f'<tr><td><a href="#{_e(_anchor(s["student"]))}">{_e(_who(s["student"]))}'
                     f'</a></td><td class="num">{s["score"]}/{s["episodes"]}</td>'
                     f'<td class="num">{_median(s)}</td><td class="num">{s["fell"]}</td>'
                     f'<td>{_e(_cheated(s))}</td><td class="num">{s["crashed"]}</td></tr>')
    parts.append('</table>')
    by_student = _by_student(episodes)
    for s in table:
        parts.append(_student_html(s, by_student.get(s['student'], {})))
    parts.append('</body></html>\n')
    return '\n'.join(parts)


def _student_html(summary, mine):
    name = summary['student']
    parts = [f'<h2 id="{_e(_anchor(name))}">{_e(_who(name))}: {summary["score"]}/'
             f'{summary["episodes"]}</h2>']
    if not mine:
        return parts[0] + '<p>No episode ran.</p>'
    parts.append('<table><tr><th>#</th><th>placement</th><th>outcome</th><th>time to kick</th>'
                 '<th>notes</th></tr>')
    for index, e in sorted(mine.items()):
        won = success(e)
        notes = ([f'cheated: {e["cheated"]}'] if e.get('cheated') else []) + list(e['notes'])
        extra = []
        if not won and e.get('video'):
            extra.append(f'<a href="{_e(quote(e["video"], errors="replace"))}">video</a>')
        if not won and e.get('output_tail'):
            extra.append('<details><summary>output, last lines</summary><pre>'
                         + _e('\n'.join(e['output_tail'])) + '</pre></details>')
        kick = _number(e['time_to_kick'], '{:.1f} s', '-')
        css = ' class="won"' if won else ' class="cheated"' if e.get('cheated') else ''
        parts.append(f'<tr{css}><td class="num">{index}</td>'
                     f'<td>{_e(placement_text(e["robot"], e["ball"]))}</td>'
                     f'<td>{_e(mark(e))} ({_e(e["ended"])})</td><td class="num">{kick}</td>'
                     f'<td>{" ".join([_e("; ".join(notes))] + extra)}</td></tr>')
    parts.append('</table>')
    return '\n'.join(parts)
