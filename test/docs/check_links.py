#!/usr/bin/python3
"""Every relative link and #anchor in the user documentation resolves (ctest docs_links).

Checked: README.md, every markdown file under docs/, and every README.md of a package or tool
folder. A link `[text](target)` or `![alt](target)` outside code is checked unless it has a URL
scheme (http:, https:, mailto:): its path must exist relative to the file, and its #anchor must be
a heading of the target markdown file, slugged as GitHub does (lower case, punctuation but `-` and
`_` dropped, spaces to `-`, repeated headings numbered -1, -2, ...).

Usage: check_links.py [ROOT] (default: the repository holding this script). Prints every broken
link as FILE:LINE: target: why, and exits 1 if there is any.
"""
import os
import re
import sys

LINK = re.compile(r'!?\[(?:[^\]\[]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+"[^"]*")?\s*\)')
SCHEME = re.compile(r'^[a-zA-Z][a-zA-Z0-9+.-]*:')


def documents(root):
    found = []
    if os.path.isfile(os.path.join(root, 'README.md')):
        found.append(os.path.join(root, 'README.md'))
    for base, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs if not d.startswith('.') and d != 'build')
        rel = os.path.relpath(base, root)
        for f in sorted(files):
            path = os.path.join(base, f)
            in_docs = rel == 'docs' or rel.startswith('docs' + os.sep)
            if f.endswith('.md') and (in_docs or (f == 'README.md' and rel != '.')):
                found.append(path)
    return found


def strip_code(lines):
    """The lines with fenced blocks blanked and inline code removed (links there are not links)."""
    out, fenced = [], False
    for line in lines:
        if re.match(r'^\s*(```|~~~)', line):
            fenced = not fenced
            out.append('')
            continue
        out.append('' if fenced else re.sub(r'`[^`]*`', '', line))
    return out


def slug(heading):
    text = re.sub(r'!?\[([^\]]*)\]\([^)]*\)', r'\1', heading)  # a link's text
    text = text.replace('`', '').strip().lower()
    text = re.sub(r'[^\w\- ]', '', text)
    return text.replace(' ', '-')


def anchors(path, cache={}):
    if path not in cache:
        seen, result = {}, set()
        with open(path, encoding='utf-8') as f:
            lines = f.read().splitlines()
        fenced = False
        for line in lines:
            if re.match(r'^\s*(```|~~~)', line):
                fenced = not fenced
                continue
            m = None if fenced else re.match(r'^#{1,6}\s+(.*?)\s*#*\s*$', line)
            if m:
                s = slug(m.group(1))
                n = seen.get(s, 0)
                seen[s] = n + 1
                result.add(s if n == 0 else '%s-%d' % (s, n))
            for a in re.findall(r'<a\s+(?:name|id)="([^"]+)"', line):
                result.add(a)
        cache[path] = result
    return cache[path]


def check(path):
    problems = []
    with open(path, encoding='utf-8') as f:
        lines = strip_code(f.read().splitlines())
    for number, line in enumerate(lines, 1):
        for target in LINK.findall(line):
            if SCHEME.match(target):
                continue
            file_part, _, anchor = target.partition('#')
            dest = os.path.normpath(os.path.join(os.path.dirname(path), file_part)) if file_part else path
            if not os.path.exists(dest):
                problems.append((path, number, target, 'no such file or directory'))
                continue
            if anchor:
                if not dest.endswith('.md') or os.path.isdir(dest):
                    problems.append((path, number, target, 'an anchor into a file that is not markdown'))
                elif anchor not in anchors(dest):
                    problems.append((path, number, target, 'no heading with anchor #%s in %s' % (anchor, dest)))
    return problems


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else
                           os.path.join(os.path.dirname(os.path.realpath(__file__)), '..', '..'))
    docs = documents(root)
    if not docs:
        print('check_links: no markdown files under %s' % root)
        return 1
    problems = [p for d in docs for p in check(d)]
    for path, number, target, why in problems:
        print('%s:%d: %s: %s' % (os.path.relpath(path, root), number, target, why))
    print('check_links: %d files, %d broken links' % (len(docs), len(problems)))
    return 1 if problems else 0


if __name__ == '__main__':
    sys.exit(main())
