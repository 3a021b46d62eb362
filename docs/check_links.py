#!/usr/bin/env python3
"""Check the relative links of README.md and docs/**/*.md: every [text](path#anchor) must
name an existing file inside the repository, and every #anchor a heading of its target.
Run from anywhere: `python3 docs/check_links.py`; exit status 1 lists the dead links."""
import pathlib, re, sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
LINK = re.compile(r'\]\(([^)\s]+)\)')


def slug(heading):
    # GitHub's anchors: lower case, punctuation dropped, spaces to hyphens.
    s = heading.strip().lower()
    s = re.sub(r'[^\w\- ]', '', s)
    return s.replace(' ', '-')


def anchors(path):
    text = re.sub(r'```.*?```', '', path.read_text(), flags=re.S)
    return {slug(m) for m in re.findall(r'^#+\s+(.*)$', text, flags=re.M)}


def main():
    files = [ROOT / 'README.md'] + sorted((ROOT / 'docs').rglob('*.md'))
    dead = []
    for f in files:
        text = re.sub(r'```.*?```', '', f.read_text(), flags=re.S)
        for target in LINK.findall(text):
            if re.match(r'[a-z]+:', target):
                continue  # URLs are not checked
            path, _, anchor = target.partition('#')
            dest = (f.parent / path).resolve() if path else f
            if ROOT not in dest.parents and dest != ROOT:
                dead.append(f'{f.relative_to(ROOT)}: {target} (outside the project)')
            elif not dest.exists():
                dead.append(f'{f.relative_to(ROOT)}: {target} (no such file)')
            elif anchor and (dest.is_dir() or anchor not in anchors(dest)):
                dead.append(f'{f.relative_to(ROOT)}: {target} (no such heading)')
    for d in dead:
        print(d)
    print(f'{len(files)} files, {len(dead)} dead links')
    return 1 if dead else 0


if __name__ == '__main__':
    sys.exit(main())
