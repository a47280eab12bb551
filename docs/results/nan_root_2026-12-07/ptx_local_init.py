#!/usr/bin/env python3
"""Loads of local memory (depot-relative, constant offsets) that no store on every path before them
wrote: a forward must-analysis over one PTX function. Usage: ptx_local_init.py FILE.ptx NAME_PART
(next to ptx_liveness.py). Stores at variable offsets (the BVH local stack) are left out, and the
SceneView parameter's copy loop counts for its 168 bytes; calls store nothing."""
import re, sys
sys.path.insert(0, __import__('os').path.dirname(__file__))
from ptx_liveness import split_functions, parse
text = open(sys.argv[1]).read()
pat = sys.argv[2]
SIZE = {'u8':1,'s8':1,'b8':1,'u16':2,'s16':2,'b16':2,'f16':2,'u32':4,'s32':4,'b32':4,'f32':4,'u64':8,'s64':8,'b64':8,'f64':8}
for name, body in split_functions(text):
    if pat not in name: continue
    stmts = parse(body)
    base = {}  # reg -> offset from depot
    # blocks
    blocks, cur = [], {'labels': [], 'ins': []}
    for k, v in stmts:
        if k == 'label':
            if cur['ins']: blocks.append(cur); cur = {'labels': [], 'ins': []}
            cur['labels'].append(v); continue
        cur['ins'].append(v)
        core = re.sub(r'^@!?%\w+\s+', '', v); op = core.split(' ')[0]
        if op.startswith(('bra', 'ret', 'exit')): blocks.append(cur); cur = {'labels': [], 'ins': []}
    if cur['ins'] or cur['labels']: blocks.append(cur)
    lab = {l: i for i, b in enumerate(blocks) for l in b['labels']}
    succ = []
    for i, b in enumerate(blocks):
        s = []
        last = b['ins'][-1] if b['ins'] else ''
        core = re.sub(r'^@!?%\w+\s+', '', last); op = core.split(' ')[0] if core else ''
        if op.startswith('bra'):
            t = core.split(' ')[-1]
            if t in lab: s.append(lab[t])
            if last.startswith('@') and i + 1 < len(blocks): s.append(i + 1)
        elif op.startswith(('ret', 'exit')):
            if last.startswith('@') and i + 1 < len(blocks): s.append(i + 1)
        elif i + 1 < len(blocks): s.append(i + 1)
        succ.append(s)
    # depot-relative registers (global over the function: add.u64 %rdX, %SP(L), N  and add.s64 %rdY, %rdX, const)
    for b in blocks:
        for v in b['ins']:
            m = re.match(r'add\.[us]64 (%rd\d+), (%SPL|%SP), (-?\d+)$', v)
            if m: base[m.group(1)] = int(m.group(3))
            m = re.match(r'mov\.u64 (%rd\d+), (%SPL|%SP)$', v)
            if m: base[m.group(1)] = 0
    derived = {}
    for b in blocks:
        for v in b['ins']:
            m = re.match(r'add\.s64 (%rd\d+), (%rd\d+), (%rd\d+)$', v)
            if m and m.group(2) in base: derived[m.group(1)] = base[m.group(2)]
    ALL = (1 << 4096) - 1
    def accesses(v):
        # (kind, offset, size) for local loads/stores with a known address
        m = re.match(r'^(?:@!?%\w+\s+)?(ld|st)(?:\.local|\.generic)?((?:\.v[24])?)\.(\w+) (.*)$', v)
        if not m: return None
        kind, vec, ty, rest = m.group(1), m.group(2), m.group(3), m.group(4)
        if '.param' in v or '.global' in v or '.shared' in v or '.const' in v: return None
        addr = re.search(r'\[(%\w+)(?:\+(-?\d+))?\]', rest)
        if not addr: return None
        if addr.group(1) not in base:
            if kind == 'st' and addr.group(1) in derived: return ('st_unknown', derived[addr.group(1)], 0)
            return ('st_unknown', -1, 0) if kind == 'st' and '.local' in v else None
        n = SIZE.get(ty, 4) * (int(vec[2]) if vec else 1)
        return kind, base[addr.group(1)] + int(addr.group(2) or 0), n
    def mask(o, n): return ((1 << n) - 1) << o
    init_in = [ALL] * len(blocks); init_in[0] = 0
    unknown = []
    def transfer(i, state, report=None):
        for v in blocks[i]['ins']:
            core = re.sub(r'^@!?%\w+\s+', '', v)
            if core.startswith('call'): continue
            a = accesses(v)
            if not a: continue
            kind, o, n = a
            if kind == 'st_unknown':
                if o == 0: state |= mask(0, 168)  # the SceneView parameter's copy loop
                else: unknown.append(v)
                continue
            if kind == 'st' and not v.startswith('@'): state |= mask(o, n)
            elif kind == 'ld' and report is not None and (state & mask(o, n)) != mask(o, n):
                report.append((o, n, v))
        return state
    changed = True
    while changed:
        changed = False
        for i in range(len(blocks)):
            out = transfer(i, init_in[i])
            for s in succ[i]:
                new = init_in[s] & out
                if new != init_in[s]: init_in[s] = new; changed = True
    reports = []
    for i in range(len(blocks)): transfer(i, init_in[i], reports)
    print('unknown-address local stores:', len(set(unknown)), sorted(set(unknown))[:5])
    print(name[:100], len(blocks), 'blocks; loads of possibly unstored local bytes:', len(reports))
    for o, n, v in reports[:30]: print('  ', o, n, v)
