#!/usr/bin/env python3
"""The include rules of docs/architecture.md ("Layers"), checked over renderer/ and materials/.

1. A file includes only its own layer or a lower one (the order is LAYERS below, written once).
2. No loop between rooms (a folder, or an inner room such as renderer/render/spatial/).
3. No loop between units (a .h and its .cpp are one unit).
Prints every violation and exits 1; exits 0 when there is none. Usage: check_layers.py [source-dir]

KNOWN_LOOPS were the loops that were there when this check was written, each work still to do
(docs/architecture.md, "Layers"); the last one (renderer/render <-> renderer/render/spatial) was
broken by giving renderer/render/ its rooms, so the list is empty and the check fails on any loop.
It also fails on a listed loop that is gone, so the list can only shrink.
"""
import os
import re
import sys

# Lowest first. A layer may include itself and the layers before it.
LAYERS = ["core", "numerics", "formats", "spectral", "image", "plot", "mesh", "materials", "scene", "camera", "render",
          "analysis", "interop", "view", "validation", "sweep", "diagnose", "cli"]
KNOWN_LOOPS = set()
INCLUDE = re.compile(r'^\s*#\s*include\s+"((?:renderer|materials)/[^"]+)"', re.M)


def layer_of(path):
    parts = path.split("/")
    return "materials" if parts[0] == "materials" else parts[1]


def room_of(path):
    return os.path.dirname(path)


def unit_of(path):
    return os.path.splitext(path)[0]


def sources(root):
    for top in ("renderer", "materials"):
        for d, _, files in os.walk(os.path.join(root, top)):
            for f in files:
                if f.endswith((".h", ".cpp")):
                    yield os.path.relpath(os.path.join(d, f), root)


def cycles(graph):
    """Strongly connected components with more than one node (Tarjan, iterative)."""
    index, low, on, stack, out, counter = {}, {}, set(), [], [], [0]
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph.get(start, ()))))]
        index[start] = low[start] = counter[0]
        counter[0] += 1
        stack.append(start)
        on.add(start)
        while work:
            node, it = work[-1]
            nxt = next(it, None)
            if nxt is not None:
                if nxt not in index:
                    index[nxt] = low[nxt] = counter[0]
                    counter[0] += 1
                    stack.append(nxt)
                    on.add(nxt)
                    work.append((nxt, iter(sorted(graph.get(nxt, ())))))
                elif nxt in on:
                    low[node] = min(low[node], index[nxt])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                comp = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.append(w)
                    if w == node:
                        break
                if len(comp) > 1:
                    out.append(sorted(comp))
    return out


def self_test():
    """The check must find what it is for: an upward include, a room loop, a file loop and a known loop
    that no longer exists."""
    import tempfile
    with tempfile.TemporaryDirectory() as root:
        files = {"renderer/core/a.h": '#include "renderer/render/b.h"\n',
                 "renderer/render/b.h": '#include "renderer/render/inner/c.h"\n',
                 "renderer/render/inner/c.h": '#include "renderer/render/b.h"\n',
                 "renderer/spectral/d.h": "", "renderer/spectral/d.cpp": '#include "renderer/spectral/e.h"\n',
                 "renderer/spectral/e.cpp": '#include "renderer/spectral/d.h"\n', "renderer/spectral/e.h": ""}
        for f, text in files.items():
            os.makedirs(os.path.join(root, os.path.dirname(f)), exist_ok=True)
            open(os.path.join(root, f), "w").write(text)
        found = check(root, known=set())
        stale = check(root, known={"renderer/spectral/d <-> renderer/spectral/e", "renderer/gone <-> renderer/away"})
    want = ["a higher layer (core < render)", "rooms include each other in a loop: renderer/render <-> renderer/render/inner",
            "files include each other in a loop: renderer/spectral/d <-> renderer/spectral/e"]
    missing = [w for w in want if not any(w in p for p in found)]
    if not any("lists a loop that is gone (remove it from the list): renderer/gone <-> renderer/away" in p for p in stale):
        missing.append("a known loop that is gone")
    print("self-test: " + ("the check finds all four planted violations" if not missing else "MISSED " + "; ".join(missing)))
    return 1 if missing or len(found) != 4 or len(stale) != 4 else 0


def main():
    if sys.argv[1:2] == ["--self-test"]:
        return self_test()
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..")
    problems = check(root)
    for p in problems:
        print(p)
    print(f"{len(problems)} include rule violation(s)" if problems else
          "layers: every include points down; no loops" + (" but the known ones (KNOWN_LOOPS)" if KNOWN_LOOPS else ""))
    return 1 if problems else 0


def check(root, known=KNOWN_LOOPS):
    problems, rooms, units = [], {}, {}
    for src in sorted(sources(root)):
        text = open(os.path.join(root, src), encoding="utf-8", errors="replace").read()
        for inc in INCLUDE.findall(text):
            a, b = layer_of(src), layer_of(inc)
            if a not in LAYERS or b not in LAYERS:
                problems.append(f"{src}: folder {a if a not in LAYERS else b} is not in the layer order")
            elif LAYERS.index(b) > LAYERS.index(a):
                problems.append(f"{src}: includes {inc}, a higher layer ({a} < {b})")
            if room_of(src) != room_of(inc):
                rooms.setdefault(room_of(src), set()).add(room_of(inc))
            if unit_of(src) != unit_of(inc):
                units.setdefault(unit_of(src), set()).add(unit_of(inc))
    found = set()
    for kind, graph in (("rooms", rooms), ("files", units)):
        for c in cycles(graph):
            loop = " <-> ".join(c)
            found.add(loop)
            if loop not in known:
                problems.append(f"{kind} include each other in a loop: {loop}")
    for loop in sorted(known - found):
        problems.append(f"KNOWN_LOOPS lists a loop that is gone (remove it from the list): {loop}")
    return problems


if __name__ == "__main__":
    sys.exit(main())
