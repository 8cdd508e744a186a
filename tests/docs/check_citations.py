#!/usr/bin/env python3
"""check_citations.py: every file and section the code and the docs cite must exist.

Purpose: a comment or a page that cites `docs/DESIGN.md, "The quadtree contract"` is only
useful while that page has that section. This checker walks the source tree and fails,
naming the file and line, on
  1. a citation of a Markdown file that is not in the repository: `NAME.md` (bare, or with a
     path) resolved next to the citing file, then in docs/, bench/ and the root;
  2. a citation of a section that the cited file has no heading for: `NAME.md, "Section"`,
     `NAME.md "Section"`, `NAME.md ("Section")` or `NAME.md#anchor`, where a quoted section
     may wrap over comment lines and matches a heading's text (without its Markdown marks);
  3. a Markdown link `[text](target)` in a .md file whose target file or #anchor is missing;
  4. a path in backticks in a .md file (`dynmesh/src/...`, `tests/...`) that does not exist;
  5. any mention of the team's notes outside the repository (`shared/`).
Invariants: read-only; the exit status is 0 exactly when no problem was found.
Complexity: O(total size of the text files).
Paper: none.

Usage: check_citations.py [--root DIR] | --self-test
"""
import argparse
import os
import re
import sys
import tempfile

TEXT_SUFFIXES = ('.hpp', '.cpp', '.h', '.py', '.sh', '.cmake', '.md', '.txt', '.toml', '.in', '.gp')
SKIP_DIRS = {'.git', 'build', 'corpus', '__pycache__', 'data', 'figures', 'artifacts'}
TOP_DIRS = ('sac-runtime/', 'dynmesh/', 'tests/', 'bench/', 'docs/', 'cmake/', 'examples/', '.ci/')
# A comment's line prefix, removed when a quoted section wraps onto the next line.
WRAP = re.compile(r'\n[ \t]*(?://+|#+|\*+)?[ \t]*')
CITE = re.compile(r'((?:[\w.-]+/)*[A-Z][A-Z0-9_]*\.md)'
                  r'(?:(?:,|\'s)?[ \t]*\(?[ \t]*["“]([^"”]{1,200})["”]|#([\w-]+))?')
LINK = re.compile(r'\[[^\]\n]*\]\(([^)\s]+)\)')
TICKED = re.compile(r'`([^`\s]+)`')
SHARED = re.compile(r'(?<![\w-])(?:\.\./)+shared/|(?<![\w./-])shared/(?:DESIGN|STYLE|FORMATS|seed)')


def text_files(root):
    for base, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs if d not in SKIP_DIRS and not d.startswith('build'))
        for f in sorted(files):
            if f.endswith(TEXT_SUFFIXES) or f == 'CMakeLists.txt' or f in ('dev.sh', 'run'):
                yield os.path.join(base, f)


def plain(heading):
    """A heading's text without Markdown marks, as a citation quotes it."""
    h = re.sub(r'[`*_]', '', heading).strip()
    return re.sub(r'\s+', ' ', h)


def slug(heading):
    """GitHub's anchor for a heading."""
    h = plain(heading).lower()
    h = re.sub(r'[^\w\- ]', '', h)
    return h.replace(' ', '-')


class Headings:
    def __init__(self):
        self.cache = {}

    def of(self, path):
        if path not in self.cache:
            names, in_code = [], False
            with open(path, encoding='utf-8', errors='replace') as f:
                for line in f:
                    if line.startswith('```'):
                        in_code = not in_code
                    elif not in_code and re.match(r'#{1,6} ', line):
                        names.append(line.lstrip('#').strip())
            self.cache[path] = names
        return self.cache[path]


def resolve(root, citing, name):
    """The file a citation names, or None: next to the citing file, then in the usual places."""
    if name.startswith('../shared') or name.startswith('shared/'):
        return None
    here = os.path.dirname(citing)
    candidates = [os.path.join(here, name), os.path.join(root, name)]
    if '/' not in name:
        candidates += [os.path.join(root, d, name) for d in ('docs', 'bench')]
    else:  # a path relative to dynmesh/ or a tool's folder, as sources write them
        candidates += [os.path.join(root, 'dynmesh', name)]
    for c in candidates:
        if os.path.isfile(c):
            return os.path.normpath(c)
    return None


def section_exists(headings, section):
    """A heading's text, or its start up to a colon, a bracket or a dash, matches the quote."""
    want = plain(section).rstrip('.,;:').lower()
    for h in headings:
        have = plain(h).lower()
        if have == want or (have.startswith(want) and re.match(r' *[:(,—-]', have[len(want):])):
            return True
    return False


def path_exists(root, p):
    """A path as the docs write it: from the root, a public header as it is included
    (`dynmesh/box.hpp`), or a program by its source's name (`bench/dynmesh_hpu_locality`)."""
    full = os.path.join(root, p)
    if os.path.exists(full) or os.path.exists(full + '.cpp'):
        return True
    return any(os.path.exists(os.path.join(root, lib, 'include', p)) for lib in ('dynmesh', 'sac-runtime'))


def check(root):
    problems = []
    heads = Headings()
    root = os.path.abspath(root)
    for path in text_files(root):
        rel = os.path.relpath(path, root)
        if rel == os.path.join('tests', 'docs', 'check_citations.py'):
            continue
        with open(path, encoding='utf-8', errors='replace') as f:
            text = f.read()
        line_of = lambda pos: text.count('\n', 0, pos) + 1
        for m in SHARED.finditer(text):
            problems.append(f'{rel}:{line_of(m.start())}: cites the team notes outside the repository ({m.group(0)})')
        joined = WRAP.sub(' ', text)
        # Map positions of `joined` back to lines: count the newlines removed before each.
        offsets = []  # (joined position, original line)
        jpos, line = 0, 1
        for piece in re.split('(' + WRAP.pattern + ')', text):
            if piece.startswith('\n'):
                line += 1
                jpos += 1
            else:
                offsets.append((jpos, line))
                jpos += len(piece)

        def jline(pos):
            best = 1
            for p, l in offsets:
                if p > pos:
                    break
                best = l
            return best

        for m in CITE.finditer(joined):
            name, section, anchor = m.group(1), m.group(2), m.group(3)
            if 'shared/' in name:
                continue  # reported above
            if path.endswith('.md') and joined[m.start() - 1:m.start()] == '(':
                continue  # a link's target: the link rule below checks it
            target = resolve(root, path, name)
            where = f'{rel}:{jline(m.start())}'
            if target is None:
                problems.append(f'{where}: cites {name}, which is not in the repository')
                continue
            hs = heads.of(target)
            if section is not None and not section_exists(hs, section):
                problems.append(f'{where}: cites section "{section}" of {name}, which has no such heading')
            if anchor is not None and anchor not in {slug(h) for h in hs}:
                problems.append(f'{where}: cites {name}#{anchor}, which has no such heading')
        if not path.endswith('.md'):
            continue
        in_code = False
        for n, line_text in enumerate(text.split('\n'), 1):
            if line_text.startswith('```'):
                in_code = not in_code
                continue
            if in_code:
                continue
            for m in LINK.finditer(line_text):
                target = m.group(1)
                if re.match(r'[a-z]+:', target):
                    continue
                file_part, _, anchor = target.partition('#')
                full = os.path.normpath(os.path.join(os.path.dirname(path), file_part)) if file_part else path
                if not os.path.exists(full):
                    problems.append(f'{rel}:{n}: links to {file_part}, which is not in the repository')
                elif anchor and full.endswith('.md') and anchor not in {slug(h) for h in heads.of(full)}:
                    problems.append(f'{rel}:{n}: links to {target}, which has no such heading')
            for m in TICKED.finditer(line_text):
                p = m.group(1).rstrip('.,:;')
                if not p.startswith(TOP_DIRS) or any(c in p for c in '*<>{}$…'):
                    continue
                p = p.split(':')[0]
                if not path_exists(root, p):
                    problems.append(f'{rel}:{n}: names {p}, which is not in the repository')
    return problems


def self_test():
    """The checker must catch each kind of problem it claims to, and pass a clean tree."""
    with tempfile.TemporaryDirectory() as root:
        def write(rel, text):
            full = os.path.join(root, rel)
            os.makedirs(os.path.dirname(full), exist_ok=True)
            with open(full, 'w', encoding='utf-8') as f:
                f.write(text)
        write('docs/DESIGN.md', '# Design\n\n## The quadtree contract\n\n### `read_many`, a read\n')
        write('dynmesh/a.hpp', '// see docs/DESIGN.md, "The quadtree\n// contract", and DESIGN.md "`read_many`, a read"\n')
        write('docs/OK.md', '[d](DESIGN.md#the-quadtree-contract) and `dynmesh/a.hpp`\n')
        if check(root):
            print('self-test: a clean tree was reported:', check(root))
            return 1
        cases = {
            'dynmesh/b.hpp': '// docs/MISSING.md\n',
            'dynmesh/c.hpp': '// docs/DESIGN.md, "No such section"\n',
            'docs/L.md': '[x](NOPE.md)\n',
            'docs/M.md': '[x](DESIGN.md#no-such-anchor)\n',
            'docs/N.md': 'see `dynmesh/src/gone.hpp`\n',
            'dynmesh/d.hpp': '// ../shared/DESIGN.md\n',
        }
        for rel, text in cases.items():
            write(rel, text)
            found = check(root)
            if len(found) != 1 or not found[0].startswith(rel):
                print(f'self-test: {rel} ({text.strip()!r}) gave {found}')
                return 1
            os.remove(os.path.join(root, rel))
    print('self-test: passed')
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--root', default=os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..'))
    ap.add_argument('--self-test', action='store_true')
    args = ap.parse_args()
    if args.self_test:
        return self_test()
    problems = check(args.root)
    for p in problems:
        print(p)
    print(f'check_citations: {len(problems)} problem(s)')
    return 1 if problems else 0


if __name__ == '__main__':
    sys.exit(main())
