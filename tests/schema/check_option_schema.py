#!/usr/bin/env python3
"""The option schema's two rules, checked on the headers (docs/architecture.md, "Options"):

1. an option's key is its field's name: f(prefix + "KEY", o.FIELD, ...) with KEY == FIELD (for
   a field of a member struct, o.member.FIELD, its last name);
2. its description in visit_options() is its only doc: the field's declaration carries no ///
   comment of its own.

Usage: check_option_schema.py INCLUDE_DIR. Prints each violation with file and line; exit 1
when there is one.
"""
import pathlib
import re
import sys

VISIT = re.compile(r'void visit_options\((\w+)(?:<\w+>)?& o\b')
OPTION = re.compile(r'f\(prefix \+ "([a-z0-9_]+)",\s*o\.([a-z0-9_.]+)\s*,')


def struct_bodies(sources):
    """struct name -> (path, first line number, body lines)."""
    out = {}
    for path, text in sources.items():
        for m in re.finditer(r'^struct (\w+) \{\n(.*?)^\};', text, re.S | re.M):
            out[m.group(1)] = (path, text.count('\n', 0, m.start(2)) + 1, m.group(2).split('\n'))
    return out


def main(include_dir):
    sources = {p: p.read_text() for p in sorted(pathlib.Path(include_dir).rglob('*.hpp'))}
    structs = struct_bodies(sources)
    problems, checked = [], 0
    for path, text in sources.items():
        visits = list(VISIT.finditer(text))
        for i, v in enumerate(visits):
            end = visits[i + 1].start() if i + 1 < len(visits) else len(text)
            for m in OPTION.finditer(text, v.end(), end):
                checked += 1
                key, field = m.group(1), m.group(2)
                line = text.count('\n', 0, m.start()) + 1
                if key != field.split('.')[-1]:
                    problems.append(f'{path}:{line}: key "{key}" is not its field\'s name ({field})')
                if '.' in field or v.group(1) not in structs:
                    continue
                spath, first, body = structs[v.group(1)]
                decl = re.compile(r'^\s+[\w:<>, ]+[\w>]\s+' + field + r'\s*(=[^;]*|\{[^;]*\})?;')
                for k, ln in enumerate(body):
                    if decl.match(ln):
                        if '///' in ln or (k > 0 and body[k - 1].strip().startswith('///')):
                            problems.append(f'{spath}:{first + k}: {v.group(1)}::{field} has a doc comment beside its '
                                            f'description in visit_options ({path}:{line}): keep one')
                        break
    for p in problems:
        print(p)
    print(f'check_option_schema: {checked} options, {len(problems)} problems')
    return 1 if problems or checked == 0 else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1]))
