"""A type's definition as ``ros2 interface show`` prints it: the installed file, and under
each field of a message type that type's definition, a tab further in.

Each line is read by rosidl's own parser (rosidl_adapter), as ros2 reads it, so that the
same comments are kept: by default every line of the type's own file, and of a nested
type's what the parser does not take for a comment of a field (a lone '#', a constant's
comment, an indented comment line); with every comment (--all-comments) or none, blank
lines neither (--no-comments).
"""
import contextlib
import io

from miro_ball.common.definitions import definition_file, split_type

# Nested types a tab further in each: a message holds a few levels (SensorsPackage: 4). An
# installed file that names itself would otherwise recurse without end.
MAX_NESTING = 32


def shown(type_name, comments=True, nested_comments=False, depth=0):
    """The lines of type_name's definition; comments: keep its own comments (and blank
    lines), nested_comments: those of the types it holds. ValueError in one line for a
    type not installed, a file rosidl can not read, or nesting past MAX_NESTING."""
    from rosidl_adapter.parser import (ACTION_REQUEST_RESPONSE_SEPARATOR, InvalidSpecification,
                                       InvalidValue, parse_message_string,
                                       SERVICE_REQUEST_RESPONSE_SEPARATOR)

    if depth > MAX_NESTING:
        raise ValueError(f'{type_name}: types nested over {MAX_NESTING} deep (does a type '
                         'hold itself?)')
    package, _, name = split_type(type_name)
    lines = []
    for number, text in enumerate(definition_file(type_name).read_text().splitlines(), 1):
        text = text.rstrip()
        spec = None
        if text not in (SERVICE_REQUEST_RESPONSE_SEPARATOR, ACTION_REQUEST_RESPONSE_SEPARATOR):
            try:  # the parser prints a line of its own to stderr before it raises
                with contextlib.redirect_stderr(io.StringIO()):
                    spec = parse_message_string(package, name, text)
            except (InvalidSpecification, InvalidValue, ValueError, NameError) as err:
                raise ValueError(f'{type_name}: line {number} can not be read: '
                                 f'{" ".join(str(err).split())[:200]}') from None
        field = spec.fields[0] if spec is not None and spec.fields else None
        if not comments:
            if not text or (spec is not None and spec.annotations.get('comment')):
                continue
            trailing = field.annotations.get('comment') if field is not None else None
            if trailing:
                text = text[:text.find(trailing[0]) - 1].strip()
        lines.append('\t' * depth + text if text else '')
        if field is not None and '/' in str(field.type):
            nested = str(field.type).split('[', 1)[0].replace('/', '/msg/')
            lines += shown(nested, nested_comments, nested_comments, depth + 1)
    return lines
