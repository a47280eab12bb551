#!/usr/bin/env python3
"""Registers read before any write on some path of each PTX function (backward liveness at entry).

Usage: ptx_liveness.py FILE.ptx [NAME_PART]. Used on `nvcc -O3 -arch=compute_90 -ptx` of
src/pvr/cuda/eye_pass.cu (with build/CMakeFiles/pvr_cuda.dir/includes_CUDA.rsp): the listed kernel
has none; CUB's radix sort and the kNN heap inside shadePixel show known benign ones. Registers
only: local memory is not tracked."""
import re, sys
from collections import defaultdict

SREG = re.compile(r'^%(tid|ntid|ctaid|nctaid|laneid|warpid|nwarpid|smid|nsmid|gridid|clock|clock64|globaltimer|lanemask_\w+|pm\d|envreg\d+|dynamic_smem_size|total_smem_size|aggr_smem_size|reserved_smem_offset\w*|is_explicit_cluster|cluster\w*|nclusterid|clusterid)\b')
REG = re.compile(r'%[A-Za-z_][\w]*')
NODEST = ('st.', 'red.', 'bar', 'barrier', 'membar', 'fence', 'prefetch', 'ret', 'exit', 'bra', 'trap', 'brkpt', 'call', 'cp.async', 'griddepcontrol', 'elect', 'nanosleep', 'pmevent', 'setmaxnreg', 'stmatrix', 'cp.reduce', 'mbarrier.init', 'mbarrier.inval', 'discard', 'applypriority', 'createpolicy', 'multimem.st', 'multimem.red', 'tensormap', 'wgmma.fence', 'wgmma.commit', 'wgmma.wait')

def split_functions(text):
    # yields (name, body lines) for .entry/.func
    funcs = []
    lines = text.split('\n')
    i = 0
    while i < len(lines):
        l = lines[i]
        m = re.match(r'\s*(?:\.visible\s+|\.weak\s+)?(\.entry|\.func)\s+(?:\([^)]*\)\s*)?([\w$]+)', l)
        if m:
            name = m.group(2)
            # find body start '{'
            j = i
            while '{' not in lines[j]:
                j += 1
            depth = 0; body = []
            k = j
            started = False
            while k < len(lines):
                for ch in lines[k]:
                    if ch == '{': depth += 1; started = True
                    elif ch == '}': depth -= 1
                body.append(lines[k])
                if started and depth == 0: break
                k += 1
            funcs.append((name, body))
            i = k + 1
        else:
            i += 1
    return funcs

def parse(body):
    # statements: labels and instructions
    kept = []
    for l in body:
        t = l.strip()
        if t.startswith('.') or t.startswith('//'):
            continue
        kept.append(l)
    text = '\n'.join(kept)
    text = re.sub(r'//[^\n]*', '', text)
    stmts = []
    for part in re.split(r';', text):
        part = part.strip()
        # labels may precede
        while True:
            m = re.match(r'^([\w$]+):\s*(.*)$', part, re.S)
            if m and not part.startswith('.'):
                stmts.append(('label', m.group(1)))
                part = m.group(2).strip()
            else:
                break
        part = part.strip('{} \n\t')
        if not part or part.startswith('.') or part.startswith('}'):
            continue
        stmts.append(('ins', ' '.join(part.split())))
    return stmts

def defs_uses(ins):
    guard_uses = set()
    m = re.match(r'^@!?(%\w+)\s+(.*)$', ins)
    if m:
        guard_uses.add(m.group(1)); ins = m.group(2)
    op, _, rest = ins.partition(' ')
    if op.startswith('{') or not rest and op in ('ret', 'exit'):
        pass
    regs_all = [r for r in REG.findall(rest) if not SREG.match(r)]
    if any(op.startswith(p) for p in NODEST):
        return set(), set(regs_all) | guard_uses, op, rest
    # destination: first operand
    rest_s = rest.strip()
    if rest_s.startswith('{'):
        dest_txt = rest_s[:rest_s.index('}') + 1]
        src_txt = rest_s[rest_s.index('}') + 1:]
    else:
        dest_txt, _, src_txt = rest_s.partition(',')
    d = set(r for r in REG.findall(dest_txt) if not SREG.match(r))
    u = set(r for r in REG.findall(src_txt) if not SREG.match(r)) | guard_uses
    if op.startswith('mov') and 0: pass
    return d, u, op, rest

def backward_live(gen, kill, succ, kills_all=None):
    """Live-in sets per block: gen | (union of the successors' live-in - kill), to a fixed point.
    A block in kills_all (a call that clobbers everything) passes nothing through."""
    live_in = [set() for _ in gen]
    changed = True
    while changed:
        changed = False
        for bi in range(len(gen) - 1, -1, -1):
            out = set()
            for s in succ[bi]: out |= live_in[s]
            new = gen[bi] | (set() if kills_all and kills_all[bi] else out - kill[bi])
            if new != live_in[bi]:
                live_in[bi] = new; changed = True
    return live_in


def analyze(name, body):
    stmts = parse(body)
    # basic blocks
    blocks = []  # list of dict(label, ins list, succ labels, falls)
    cur = {'labels': [], 'ins': []}
    def close(fall):
        nonlocal cur
        cur['fall'] = fall
        blocks.append(cur)
        cur = {'labels': [], 'ins': []}
    for kind, v in stmts:
        if kind == 'label':
            if cur['ins'] or cur['labels']:
                if cur['ins']:
                    close(True)
            cur['labels'].append(v)
            continue
        cur['ins'].append(v)
        core = re.sub(r'^@!?%\w+\s+', '', v)
        op = core.split(' ')[0]
        if op.startswith('bra') or op.startswith('ret') or op.startswith('exit') or op.startswith('brx'):
            close(v.startswith('@'))  # guarded branch falls through
    if cur['ins'] or cur['labels']:
        close(False)
    label_to_block = {}
    for bi, b in enumerate(blocks):
        for l in b['labels']:
            label_to_block[l] = bi
    succ = []
    for bi, b in enumerate(blocks):
        s = []
        last = b['ins'][-1] if b['ins'] else ''
        core = re.sub(r'^@!?%\w+\s+', '', last)
        op = core.split(' ')[0] if core else ''
        if op.startswith('bra'):
            tgt = core.split(' ')[-1].strip()
            if tgt in label_to_block: s.append(label_to_block[tgt])
            if last.startswith('@') and bi + 1 < len(blocks): s.append(bi + 1)
        elif op.startswith('ret') or op.startswith('exit'):
            if last.startswith('@') and bi + 1 < len(blocks): s.append(bi + 1)
        elif op.startswith('brx'):
            s.extend(range(len(blocks)))  # conservative
        else:
            if bi + 1 < len(blocks): s.append(bi + 1)
        succ.append(s)
    # gen/kill per block
    gen, kill = [], []
    for b in blocks:
        g, k = set(), set()
        for ins in b['ins']:
            d, u, _, _ = defs_uses(ins)
            g |= (u - k)
            k |= d
        gen.append(g); kill.append(k)
    live_in = backward_live(gen, kill, succ)
    return live_in[0] if blocks else set(), blocks, gen, kill, succ, live_in

if __name__ == '__main__':
    text = open(sys.argv[1]).read()
    pat = sys.argv[2] if len(sys.argv) > 2 else ''
    for name, body in split_functions(text):
        if pat not in name: continue
        li, blocks, gen, kill, succ, live_in = analyze(name, body)
        li = {r for r in li if not r.startswith('%SP') and not r.startswith('%SPL')}
        print(f'{name}: {len(blocks)} blocks, live at entry: {sorted(li)}')
