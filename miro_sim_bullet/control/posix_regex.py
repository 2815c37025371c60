"""POSIX extended regular expressions (ERE) on Python's re, for the entity name filter.

Python's re reads most of an ERE the same way; where it would read one differently this
module either translates (bracket expressions: POSIX character classes such as
[[:digit:]], a backslash that is a plain character inside brackets) or refuses with one
line (what ERE lacks and re would take as something else: escapes such as \\d or \\1,
(?...) groups, lazy or possessive repetition like *? and *+, collating elements [.x.] and
equivalence classes [=x=]). Whether a name matches is the same under POSIX's leftmost-
longest rule and re's leftmost-first one, so a search answers as regexec would.
"""
import re
import string

MAX_PATTERN = 256  # characters; a filter is a name pattern, not a program

# The POSIX classes, over ASCII: entity names are ROS names.
_CLASSES = {
    'alpha': 'a-zA-Z', 'digit': '0-9', 'alnum': '0-9a-zA-Z', 'upper': 'A-Z', 'lower': 'a-z',
    'space': r' \t\n\r\f\v', 'blank': r' \t', 'punct': re.escape(string.punctuation),
    'xdigit': '0-9A-Fa-f', 'cntrl': r'\x00-\x1f\x7f', 'print': r'\x20-\x7e',
    'graph': r'\x21-\x7e',
}
_REPEATS = '*+?}'


def compile_ere(pattern):
    """The compiled pattern, or ValueError in one line saying why it is refused."""
    if not isinstance(pattern, str):
        raise ValueError('must be a string')
    if len(pattern) > MAX_PATTERN:
        raise ValueError(f'longer than {MAX_PATTERN} characters')
    translated = _translate(pattern)
    try:
        return re.compile(translated)
    except (re.error, RecursionError, OverflowError) as err:
        raise ValueError(str(err)) from None


def _translate(pattern):
    out, i = [], 0
    while i < len(pattern):
        char = pattern[i]
        if char == '\\':
            if i + 1 == len(pattern):
                raise ValueError('a trailing backslash')
            escaped = pattern[i + 1]
            if escaped.isalnum():
                raise ValueError(f'\\{escaped} is not POSIX extended (use a bracket '
                                 'expression such as [[:digit:]])')
            out.append(re.escape(escaped))
            i += 2
            continue
        if char == '[':
            text, i = _bracket(pattern, i)
            out.append(text)
            continue
        if char == '(' and pattern[i + 1:i + 2] == '?':
            raise ValueError("'(?' is not POSIX extended")
        if char in _REPEATS and pattern[i + 1:i + 2] in ('?', '+'):
            raise ValueError(f"{char + pattern[i + 1]!r} (lazy or possessive repetition) is "
                             'not POSIX extended')
        out.append(char)
        i += 1
    return ''.join(out)


def _bracket(pattern, start):
    """Python's text for the bracket expression opening at ``start``, and where it ends."""
    i, out = start + 1, ['[']
    if pattern[i:i + 1] == '^':
        out.append('^')
        i += 1
    first = True
    while True:
        if i >= len(pattern):
            raise ValueError("an unterminated '['")
        char = pattern[i]
        if char == ']' and not first:
            return ''.join(out) + ']', i + 1
        first = False
        if char == '[' and pattern[i + 1:i + 2] in (':', '.', '='):
            kind = pattern[i + 1]
            end = pattern.find(kind + ']', i + 2)
            if end < 0:
                raise ValueError(f"an unterminated '[{kind}'")
            name = pattern[i + 2:end]
            if kind != ':':
                raise ValueError(f"'[{kind}{name}{kind}]' (collating) is not supported")
            if name not in _CLASSES:
                raise ValueError(f"no character class '[:{name}:]' "
                                 f"(classes: {', '.join(sorted(_CLASSES))})")
            out.append(_CLASSES[name])
            i = end + 2
            continue
        # Every other character is itself (a backslash too, in POSIX); '-' keeps its
        # meaning of a range, except first or last, where it is itself in both.
        out.append('-' if char == '-' else re.escape(char))
        i += 1
