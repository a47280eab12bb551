#!/usr/bin/env python3
"""Registers (R, P, UR, UP) read before any write on some path of each SASS function from
cuobjdump -sass (backward liveness at the function's entry). Calls are taken to clobber every
register and read none, a predicated write kills nothing; function live-ins beyond the ABI's argument registers are suspects.
Usage: sass_liveness.py FILE.sass [NAME_PART] [-v]. Run on the listed kernel's and an eye-rays
kernel's real dump (H100, 2026-12-07, fifteenth session: none live at entry) after its first run
there named UR7 and UR9, the upper halves of ULDC.64's destinations, which it now counts."""
import os, re, sys
from collections import defaultdict

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ptx_liveness import backward_live

INS = re.compile(r'/\*([0-9a-f]{4,})\*/\s+(.*?)\s*;')
LABEL = re.compile(r'^\s*(\.L_x_\d+):')
NODEST = ('ST', 'STG', 'STS', 'STL', 'RED', 'REDG', 'BRA', 'BRX', 'JMP', 'JMX', 'EXIT', 'RET', 'CALL', 'BAR', 'MEMBAR',
          'BSSY', 'BSYNC', 'WARPSYNC', 'NOP', 'YIELD', 'DEPBAR', 'ERRBAR', 'CCTL', 'CCTLL', 'BPT', 'KILL', 'NANOSLEEP',
          'FENCE', 'STSM', 'UTMASTG', 'SYNCS', 'ACQBULK', 'BREAK', 'BMOV', 'WARPGROUP', 'ARRIVES', 'REDUX_NODEST')
def width_of(op):
    if '.128' in op: return 4
    if '.64' in op: return 2
    return 1

def regs_in(tok, width=1):
    out = []
    for m in re.finditer(r'(?<![\w.])(U?R)(\d+)(\.64)?|(?<![\w.])(U?P)(\d)', tok):
        if m.group(1):
            kind, n = m.group(1), int(m.group(2))
            w = 2 if m.group(3) else width
            out += [f'{kind}{n + k}' for k in range(w)]
        else:
            out.append(f'{m.group(4)}{m.group(5)}')
    return out

def split_operands(rest):
    ops, depth, cur = [], 0, ''
    for ch in rest:
        if ch in '[(': depth += 1
        if ch in '])': depth -= 1
        if ch == ',' and depth == 0:
            ops.append(cur.strip()); cur = ''
        else:
            cur += ch
    if cur.strip(): ops.append(cur.strip())
    return ops

def defs_uses(text):
    guard = []
    m = re.match(r'^@(!?)(U?P\d|U?PT)\s+(.*)$', text)
    if m:
        guard = regs_in(m.group(2)); text = m.group(3)
    op, _, rest = text.partition(' ')
    base = op.split('.')[0]
    ops = split_operands(rest)
    w = width_of(op)
    if base.startswith('D') and base in ('DADD', 'DMUL', 'DFMA', 'DSETP', 'DMNMX'):
        w = 2
    uses, defs = set(guard), set()
    if base in NODEST or base.startswith('ST') and base not in ('STSM',):
        for i, o in enumerate(ops):
            if o.startswith('['):
                uses.update(regs_in(o, 1))
            else:
                uses.update(regs_in(o, w if base.startswith('ST') else 1))
        return defs, uses, base
    if base == 'CALL':
        return {'*'}, uses, base
    ndest = 1
    if base in ('SHFL',): ndest = 2
    dest_done = False
    for i, o in enumerate(ops):
        is_pred = re.fullmatch(r'!?U?P(\d|T)', o) is not None
        if i == 0:
            dw = w if base.startswith(('LD', 'ULD')) or base in ('DADD', 'DMUL', 'DFMA') else 1
            if base.startswith('IMAD') and '.WIDE' in op: dw = 2
            if base in ('F2F', 'I2F', 'F2I') and '.F64' in op.split('.', 1)[1].split('.')[0:1] + ['']: dw = 2
            if base in ('MOV', 'UMOV') and '.64' in op: dw = 2
            defs.update(regs_in(o, dw))
        elif i < ndest or (not dest_done and is_pred and i <= 2 and base not in ('SEL', 'FSEL', 'VOTE', 'VOTEU', 'PLOP3') ):
            defs.update(regs_in(o))
        else:
            dest_done = True
            uses.update(regs_in(o, 2 if ('.64' in o) else (w if base.startswith('LD') is False and w == 2 and base in ('DADD','DMUL','DFMA','DSETP') else 1)))
    if base == 'PLOP3':
        defs.update(regs_in(ops[1]) if len(ops) > 1 else [])
    return defs, uses, base

def analyze(lines):
    # statements in order, with labels
    stmts = []
    for l in lines:
        lm = LABEL.match(l)
        if lm: stmts.append(('label', lm.group(1))); continue
        m = INS.search(l)
        if m: stmts.append(('ins', m.group(2), m.group(1)))
    blocks, cur = [], {'labels': [], 'ins': []}
    def close():
        nonlocal cur
        blocks.append(cur); cur = {'labels': [], 'ins': []}
    for s in stmts:
        if s[0] == 'label':
            if cur['ins']: close()
            cur['labels'].append(s[1]); continue
        cur['ins'].append((s[1], s[2]))
        core = re.sub(r'^@!?U?P\w+\s+', '', s[1])
        b = core.split(' ')[0].split('.')[0]
        if b in ('BRA', 'BRX', 'JMP', 'JMX', 'EXIT', 'RET', 'BREAK'): close()
    if cur['ins'] or cur['labels']: close()
    lab = {l: i for i, b in enumerate(blocks) for l in b['labels']}
    succ = []
    for i, b in enumerate(blocks):
        s = []
        if not b['ins']:
            if i + 1 < len(blocks): s.append(i + 1)
            succ.append(s); continue
        text = b['ins'][-1][0]
        guarded = text.startswith('@') and not re.match(r'^@!?U?PT\s', text)
        core = re.sub(r'^@!?U?P\w+\s+', '', text)
        b0 = core.split(' ')[0].split('.')[0]
        if b0 in ('BRA', 'JMP'):
            t = re.search(r'`\((\.L_x_\d+)\)', core)
            if t and t.group(1) in lab: s.append(lab[t.group(1)])
            if guarded and i + 1 < len(blocks): s.append(i + 1)
        elif b0 in ('EXIT', 'RET'):
            if guarded and i + 1 < len(blocks): s.append(i + 1)
        elif b0 in ('BRX', 'JMX'):
            s = list(range(len(blocks)))
        else:
            if i + 1 < len(blocks): s.append(i + 1)
        succ.append(s)
    gen, kill, first_use = [], [], []
    for b in blocks:
        g, k, fu = set(), set(), {}
        allk = False
        for text, addr in b['ins']:
            d, u, base = defs_uses(text)
            if not allk:
                for r in u - k:
                    if r not in g: fu[r] = (addr, text)
                    g.add(r)
            if '*' in d: allk = True
            # A predicated write may not happen: it keeps the register's earlier value live.
            if not re.match(r'^@!?U?P\d', text): k |= d
        gen.append(g); kill.append((k, allk)); first_use.append(fu)
    live = backward_live(gen, [k for k, _ in kill], succ, [allk for _, allk in kill])
    return blocks, live, first_use, succ

if __name__ == '__main__':
    text = open(sys.argv[1]).read().split('\n')
    pat = sys.argv[2] if len(sys.argv) > 2 else ''
    funcs, name, cur = [], None, []
    for l in text:
        m = re.search(r'Function : (\S+)', l)
        if m:
            if name: funcs.append((name, cur))
            name, cur = m.group(1), []
        elif name: cur.append(l)
    if name: funcs.append((name, cur))
    for name, lines in funcs:
        if pat not in name: continue
        blocks, live, fu, succ = analyze(lines)
        entry = live[0] if live else set()
        entry = {r for r in entry if r not in ('RZ', 'PT', 'URZ', 'UPT')}
        print(f'{name[:150]}: {len(blocks)} blocks, live at entry: {sorted(entry)}')
        if '-v' in sys.argv:
            for r in sorted(entry):
                # the first block that reads r with r live-in
                for i, b in enumerate(blocks):
                    if r in fu[i] and r in live[i]:
                        print(f'   {r}: first read at {fu[i][r][0]}: {fu[i][r][1]}'); break
