#!/usr/bin/env python3
"""Uniform registers (URn) that one value keeps live over a long stretch of a kernel's SASS, and
where that register is written next: the pattern of the foveated pass's fault (a kernel's stores
reloaded UR10:UR11, which still held the local frame's address that lagging lanes of the warp
were shading through; docs/benchmarks.md, fifteenth session).

Usage: ur_live_ranges.py FILE.sass NAME_PART [MIN_SPAN_HEX]
FILE: `cuobjdump -sass` or `nvdisasm -c` text. The kernel's body runs from its first instruction to
its last unpredicated EXIT; functions it calls are not followed (a call reads and writes no UR here).
Prints each value of a UR whose uses span more than MIN_SPAN bytes of code (default 0x20000):
where it was written, its last use, and the next write of that register, if any."""
import re
import sys


def kernel_lines(text, name_part):
    """The lines of the first function whose header names NAME_PART, in either dump's format."""
    out, keep = [], False
    for line in text.split('\n'):
        header = re.search(r'Function : (\S+)|\.type\s+(\S+),@function', line)
        if header:
            name = header.group(1) or header.group(2)
            if keep:
                break
            keep = name_part in name and not name.startswith('$')
            continue
        if keep:
            out.append(line)
    return out


def instructions(lines):
    body = []
    for line in lines:
        if re.match(r'^\s*/\* 0x', line):
            continue
        m = re.search(r'/\*([0-9a-f]+)\*/\s+(.*?)\s*;', line)
        if m:
            body.append((int(m.group(1), 16), m.group(2)))
    exits = [a for a, t in body if re.match(r'^EXIT\b', t)]
    end = max(exits) if exits else body[-1][0]
    return [(a, t) for a, t in body if a <= end]


def events(body):
    for address, text in body:
        core = re.sub(r'^@!?U?P\w+\s+', '', text)
        op, _, rest = core.partition(' ')
        operands = [o.strip() for o in rest.split(',')]
        written = []
        if operands and re.fullmatch(r'UR\d+', operands[0]) and not op.startswith('ST'):
            first = int(operands[0][2:])
            written = [first + k for k in range(2 if '.64' in op else 1)]
            operands = operands[1:]
        read = [int(r) for o in operands for r in re.findall(r'\bUR(\d+)\b', o)]
        yield address, text, written, read


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    lines = kernel_lines(open(sys.argv[1]).read(), sys.argv[2])
    if not lines:
        sys.exit(f'no function named like {sys.argv[2]!r} in {sys.argv[1]}')
    min_span = int(sys.argv[3], 16) if len(sys.argv) > 3 else 0x20000
    live = {}  # register -> [written at, by, last use]
    found = []
    for address, text, written, read in events(instructions(lines)):
        for r in read:
            if r in live:
                live[r][2] = address
        for r in written:
            if r in live and live[r][2] - live[r][0] > min_span:
                found.append((r, *live[r], address, text))
            live[r] = [address, text, address]
    for r, (at, by, last) in live.items():
        if last - at > min_span:
            found.append((r, at, by, last, None, None))
    for r, at, by, last, next_at, next_by in sorted(found, key=lambda f: (f[1], f[0])):
        after = f', then written at {next_at:#x} by {next_by}' if next_at is not None else ', not written again'
        print(f'UR{r}: written at {at:#x} by {by}, last read at {last:#x}{after}')


if __name__ == '__main__':
    main()
