"""POSIX extended regular expressions (ERE) for the entity name filter, read by Python's
re parser and searched by an automaton of our own.

Python's re reads most of an ERE the same way; where it would read one differently this
module either translates (bracket expressions: POSIX character classes such as
[[:digit:]], a backslash that is a plain character inside brackets) or refuses with one
line (what ERE lacks and re would take as something else: escapes such as \\d or \\1,
(?...) groups, lazy or possessive repetition like *? and *+, collating elements [.x.] and
equivalence classes [=x=]). Whether a name matches is the same under POSIX's leftmost-
longest rule and re's leftmost-first one, so a search answers as regexec would.

The search is not re's: re backtracks, and '(a+)+$' on a name of 40 a's and a '_' would
have taken days (2**40 ways to split the a's), the simulator with it; so would 'a*a*a*...$'.
Pattern runs the expression as a set of automaton states a character instead: time linear
in the name's length, times at most the automaton's size. That size is bounded: written
out without counted repetition a pattern has about as many states as characters, and a
count that multiplies them past MAX_STATES is refused ('(.?){990}Q' had 1982 states, and a
name cost 155 times what it costs with 'a').
"""
import re
import string

try:  # re's own parse tree: what re would read
    from re import _constants as sre, _parser
except ImportError:  # Python 3.10: the same modules under their old names
    import sre_constants as sre
    import sre_parse as _parser

MAX_PATTERN = 256  # characters; a filter is a name pattern, not a program
MAX_STATES = MAX_PATTERN  # of the automaton: 'x{300}' is as big as its 300 x's
MAX_STEPS = 4096  # (states, character) steps remembered between searches: 35 MB at worst

# The POSIX classes, over ASCII: entity names are ROS names.
_CLASSES = {
    'alpha': 'a-zA-Z', 'digit': '0-9', 'alnum': '0-9a-zA-Z', 'upper': 'A-Z', 'lower': 'a-z',
    'space': r' \t\n\r\f\v', 'blank': r' \t', 'punct': re.escape(string.punctuation),
    'xdigit': '0-9A-Fa-f', 'cntrl': r'\x00-\x1f\x7f', 'print': r'\x20-\x7e',
    'graph': r'\x21-\x7e',
}
_REPEATS = '*+?}'
_STARTS = (sre.AT_BEGINNING, sre.AT_BEGINNING_STRING)
_ENDS = (sre.AT_END, sre.AT_END_STRING)


def compile_ere(pattern):
    """The Pattern, or ValueError in one line saying why it is refused."""
    if not isinstance(pattern, str):
        raise ValueError('must be a string')
    if len(pattern) > MAX_PATTERN:
        raise ValueError(f'longer than {MAX_PATTERN} characters')
    translated = _translate(pattern)
    try:
        return Pattern(_parser.parse(translated))
    except (re.error, RecursionError, OverflowError) as err:
        raise ValueError(str(err)) from None


class Pattern:
    """An expression as an automaton (Thompson's construction) over re's parse tree. A
    state is ('char', test of a character's code, next), ('split', [next, ...]), ('at',
    start or end, next) or ('match',)."""

    def __init__(self, parsed):
        self.states = [('match',)]
        self.start = self._sequence(parsed, 0)
        self._steps = {}  # (states, character, at the end after it) -> the states after it

    def search(self, text):
        """Whether the expression matches somewhere in ``text``."""
        codes = [ord(c) for c in text]
        now = self._close([self.start], True, not codes)
        for index, code in enumerate(codes):
            if 0 in now:
                return True
            key = (now, code, index + 1 == len(codes))
            if key not in self._steps:
                if len(self._steps) >= MAX_STEPS:
                    self._steps.clear()
                moved = [state[2] for state in map(self.states.__getitem__, now)
                         if state[0] == 'char' and state[1](code)]
                self._steps[key] = self._close(moved + [self.start], False, key[2])
            now = self._steps[key]
        return 0 in now

    def _close(self, roots, at_start, at_end):
        """The states reached from ``roots`` without reading a character."""
        seen, stack = set(), list(roots)
        while stack:
            index = stack.pop()
            if index in seen:
                continue
            seen.add(index)
            state = self.states[index]
            if state[0] == 'split':
                stack.extend(state[1])
            elif state[0] == 'at' and (at_start if state[1] in _STARTS else at_end):
                stack.append(state[2])
        return frozenset(seen)

    def _add(self, state):
        if len(self.states) >= MAX_STATES:
            raise ValueError(f'too complex (more than {MAX_STATES} automaton states)')
        self.states.append(state)
        return len(self.states) - 1

    def _sequence(self, items, then):
        """The first state of ``items`` (re's parse of a sequence) followed by ``then``."""
        for op, value in reversed(list(items)):
            then = self._item(op, value, then)
        return then

    def _item(self, op, value, then):
        if op in (sre.LITERAL, sre.NOT_LITERAL, sre.ANY, sre.IN):
            return self._add(('char', _test(op, value), then))
        if op == sre.SUBPATTERN:
            return self._sequence(value[-1], then)
        if op == sre.BRANCH:
            return self._add(('split', [self._sequence(branch, then) for branch in value[1]]))
        if op == sre.AT and value in _STARTS + _ENDS:
            return self._add(('at', value, then))
        if op == sre.MAX_REPEAT:  # lazy and possessive ones are refused by _translate
            low, high, body = value
            if high == sre.MAXREPEAT:  # a loop: the body again, or on
                tail = self._add(('split', []))
                self.states[tail][1].extend([self._sequence(body, tail), then])
            else:  # high - low optional copies, each of which may skip to the end
                tail = then
                for _ in range(high - low):
                    tail = self._add(('split', [self._sequence(body, tail), then]))
            for _ in range(low):
                tail = self._sequence(body, tail)
            return tail
        raise ValueError(f'{str(op).lower()} is not supported')


def _test(op, value):
    """A test of a character's code for one of re's character items."""
    if op == sre.LITERAL:
        return value.__eq__
    if op == sre.NOT_LITERAL:
        return value.__ne__
    if op == sre.ANY:
        return ord('\n').__ne__
    negate, singles, ranges = False, set(), []
    for kind, item in value:
        if kind == sre.NEGATE:
            negate = True
        elif kind == sre.LITERAL:
            singles.add(item)
        elif kind == sre.RANGE:
            ranges.append(item)
        else:
            raise ValueError(f'{str(kind).lower()} in brackets is not supported')
    return lambda code: (code in singles or any(a <= code <= b for a, b in ranges)) != negate


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
