#!/usr/bin/env python3
"""Every failing path of a routed iCEBreaker design, not just the worst (docs/gateware.md fmax-soc11).

nextpnr-ice40 reports one critical path per clock; this reads the SDF it writes with `--sdf` (cell
delays, setup times and every routed net's delay), computes the latest arrival at every register,
RAM and DSP input (a longest-path pass over the combinational graph, clock-to-out at the starts)
and prints the endpoints slower than the period: grouped by start and end register (the cell name's
prefix before yosys's _SB_* suffix), by the start's module, the N worst with the registers they
pass, and the nets of >= 8 sinks that the most failing paths cross. The worst agrees with
nextpnr's own figure (the same delays).
Written by: nextpnr-ice40 ... --sdf FILE.sdf (scripts/gateware.sh's command line plus --sdf)."""
import argparse, re, sys, collections

def tokens(text):
    for m in re.finditer(r'\(|\)|"[^"]*"|(?:\\.|[^\s()"])+', text):
        yield m.group(0)

def parse(text):
    stack = [[]]
    for t in tokens(text):
        if t == '(':
            stack.append([])
        elif t == ')':
            x = stack.pop()
            stack[-1].append(x)
        else:
            stack[-1].append(t)
    return stack[0][0]

def unesc(s):
    return re.sub(r'\\(.)', r'\1', s)

def val(v):
    # (min:typ:max) -> max in ps
    if isinstance(v, list):
        v = v[0] if v else '0'
    parts = v.split(':')
    return max(float(p) for p in parts if p != '')

def port_of(p):
    # "posedge CLK" list or name
    if isinstance(p, list):
        return p[0], unesc(p[1])
    return None, unesc(p)

def split_pin(s):
    s = unesc(s)
    i = s.rfind('/')
    return s[:i], s[i + 1:]

def arguments(argv):
    ap = argparse.ArgumentParser(
        prog='sdf_paths.py', description=__doc__.split('\n\n')[0],
        epilog='Example: python3 gateware/boards/sdf_paths.py r.sdf 30 --period 39.8 --end swap')
    ap.add_argument('sdf', help='the SDF file nextpnr-ice40 wrote with --sdf')
    ap.add_argument('top', nargs='?', type=int, default=40, help='how many worst endpoints to list (40)')
    ap.add_argument('--period', type=float, default=39.8,
                    help='the clock period in ns; endpoints slower than it fail (39.8: 25.125 MHz)')
    ap.add_argument('--end', help='print the whole path into the worst failing endpoint whose cell name '
                    'contains this')
    ap.add_argument('--start', help='with --end: only a path whose first cell name contains this')
    a = ap.parse_args(argv)
    if a.top < 0 or not (a.period > 0):
        ap.error('N must be >= 0 and --period a positive number of ns')
    return a

def main(argv):
    opt = arguments(argv)
    try:
        with open(opt.sdf) as f:
            sdf = f.read()
    except OSError as e:
        sys.exit(f"sdf_paths.py: cannot read {opt.sdf}: {e.strerror} (write it with nextpnr-ice40 ... --sdf {opt.sdf})")
    n_top = opt.top
    period = opt.period * 1000
    try:
        tree = parse(sdf)
    except (IndexError, ValueError):
        tree = None
    if not isinstance(tree, list) or not tree or tree[0] != 'DELAYFILE':
        sys.exit(f"sdf_paths.py: {opt.sdf} is not an SDF file (no balanced (DELAYFILE ...) at its start)")
    comb = collections.defaultdict(list)      # (cell, inport) -> [(outport, d)]
    clk2q = {}                                # (cell, outport) -> d
    setup = {}                                # (cell, inport) -> setup
    inter = collections.defaultdict(list)     # (cell, port) driver -> [((cell, port), d)]
    for cell in tree:
        if not isinstance(cell, list) or not cell or cell[0] != 'CELL':
            continue
        inst = ''
        for item in cell[1:]:
            if item[0] == 'INSTANCE':
                inst = unesc(item[1]) if len(item) > 1 else ''
        for item in cell[1:]:
            if item[0] == 'DELAY':
                for ab in item[1:]:
                    for e in ab[1:]:
                        if e[0] == 'IOPATH':
                            edge, a = port_of(e[1])
                            _, b = port_of(e[2])
                            d = max(val(x) for x in e[3:]) if len(e) > 3 else 0.0
                            if edge or a in ('CLK', 'RCLK', 'WCLK', 'CLOCK'):
                                clk2q[(inst, b)] = max(clk2q.get((inst, b), 0.0), d)
                            else:
                                comb[(inst, a)].append((b, d))
                        elif e[0] == 'INTERCONNECT':
                            a = split_pin(e[1])
                            b = split_pin(e[2])
                            d = max(val(x) for x in e[3:]) if len(e) > 3 else 0.0
                            inter[a].append((b, d))
            elif item[0] == 'TIMINGCHECK':
                for c in item[1:]:
                    if c[0] in ('SETUPHOLD', 'SETUP'):
                        _, a = port_of(c[1])
                        d = val(c[3]) if len(c) > 3 else 0.0
                        setup[(inst, a)] = max(setup.get((inst, a), 0.0), d)
    # arrival times: longest path, memoised DFS over the DAG from each start
    arr = {}
    pred = {}
    order = []
    # Kahn over nodes
    succ = collections.defaultdict(list)
    indeg = collections.Counter()
    nodes = set()
    for a, lst in inter.items():
        for b, d in lst:
            succ[a].append((b, d, 'net'))
            indeg[b] += 1
            nodes.add(a); nodes.add(b)
    for (c, a), lst in comb.items():
        for b, d in lst:
            if (c, a) in setup and (c, b) in clk2q:
                continue
            succ[(c, a)].append(((c, b), d, 'cell'))
            indeg[(c, b)] += 1
            nodes.add((c, a)); nodes.add((c, b))
    for k, d in clk2q.items():
        arr[k] = d
        pred[k] = None
        nodes.add(k)
    q = collections.deque(n for n in nodes if indeg[n] == 0)
    while q:
        n = q.popleft()
        order.append(n)
        for b, d, kind in succ[n]:
            if n in arr:
                t = arr[n] + d
                if t > arr.get(b, -1):
                    arr[b] = t
                    pred[b] = n
            indeg[b] -= 1
            if indeg[b] == 0:
                q.append(b)
    if len(order) != len(nodes):
        print(f"# warning: {len(nodes) - len(order)} nodes in loops not timed", file=sys.stderr)
    fanout = {a: len(lst) for a, lst in inter.items()}
    ends = []
    for k, s in setup.items():
        if k in arr:
            ends.append((arr[k] + s, k))
    ends.sort(reverse=True)

    def reg(cell):
        c = cell
        m = re.match(r'(.*?)_SB_(DFF|RAM|MAC|SPRAM)', c)
        if m:
            c = m.group(1)
        else:
            c = re.sub(r'(_SB_LUT4.*|_SB_CARRY.*|_LC$|_DFFLC$)', '', c)
        return c.replace('u_gpu.', '')

    def path_of(k):
        p = []
        while k is not None:
            p.append(k)
            k = pred.get(k)
        return p[::-1]

    if not ends:
        sys.exit(f"sdf_paths.py: {opt.sdf} has no timed endpoint (no register input with a setup time is reached)")
    print(f"# {len(ends)} timed endpoints; worst {ends[0][0]/1000:.2f} ns ({1e6/ends[0][0]:.2f} MHz); "
          f"endpoints over {period/1000:.1f} ns: {sum(1 for t, _ in ends if t > period)}")
    groups = collections.defaultdict(lambda: [0, 0.0, None])
    rows = []
    for t, k in ends:
        if t <= period:
            break
        p = path_of(k)
        start = p[0]
        key = (reg(start[0]), reg(k[0]))
        g = groups[key]
        g[0] += 1
        if t > g[1]:
            g[1] = t
            # highest-fanout driver on the path
            drivers = [(fanout.get(n, 0), n) for n in p if n in fanout]
            g[2] = max(drivers) if drivers else None
        rows.append((t, k, p))
    print("## failing endpoints grouped by (start register, end register): count, worst ns, highest-fanout driver on the worst")
    for key, (cnt, t, fo) in sorted(groups.items(), key=lambda x: -x[1][1]):
        fo_s = f"{fo[0]} sinks: {reg(fo[1][0])}.{fo[1][1]}" if fo else ""
        print(f"{t/1000:6.2f} ns  x{cnt:3d}  {key[0]}  ->  {key[1]}   [{fo_s}]")
    cat = collections.defaultdict(lambda: [0, 0.0, None])
    for t, k, p in rows:
        st = reg(p[0][0]).split('.')
        key = '.'.join(st[:2]) if st[0] == 'u_soc' else st[0]
        c = cat[key]
        c[0] += 1
        if t > c[1]:
            c[1] = t
            c[2] = reg(k[0])
    print("## failing endpoints by the start's module: count, worst ns, its end")
    for key, (n, t, e) in sorted(cat.items(), key=lambda x: -x[1][1]):
        print(f"CAT {key:24s} x{n:4d} {t/1000:6.2f} ns -> {e}")
    if opt.end:
        for t, k, p in rows:
            if opt.end in k[0] and (not opt.start or opt.start in p[0][0]):
                print(f"## path into {k}: {t/1000:.2f} ns")
                for n in p:
                    print(f"   {arr[n]/1000:6.2f}  fo {fanout.get(n, 0):3d}  {n[0].replace('u_gpu.', '')}.{n[1]}")
                break
    print(f"## the {n_top} worst endpoints, with the cells (registers / module prefixes) on the path")
    for t, k, p in rows[:n_top]:
        mods = []
        for n in p:
            r = reg(n[0])
            if not mods or mods[-1] != r:
                mods.append(r)
        print(f"{t/1000:6.2f} {k[0].replace('u_gpu.', '')}.{k[1]}  ({len(p)} pins): " + " > ".join(mods))
    # most frequent high-fanout drivers over all failing paths
    cnt = collections.Counter()
    for t, k, p in rows:
        for n in set(p):
            if fanout.get(n, 0) >= 8:
                cnt[n] += 1
    print("## high-fanout drivers (>= 8 sinks) by how many failing endpoints' worst paths cross them")
    for n, c in cnt.most_common(25):
        print(f"x{c:4d}  fanout {fanout[n]:3d}  {n[0].replace('u_gpu.', '')}.{n[1]}")

if __name__ == '__main__':
    main(sys.argv[1:])
