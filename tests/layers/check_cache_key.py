#!/usr/bin/env python3
"""The layered tables' cache key (CMakeLists.txt, "The layered tables' cache key") checked
independently: the files the build hashed must be the fill's include closure computed here (the
fill's sources, everything they include, and the .cpp beside each such header of renderer/render/
and materials/), and the hash compiled in must be the SHA-256 of their current contents, so that
touching any of them gives a new key. A planted change to one of them must change the hash.
Usage: check_cache_key.py <source-dir> <build>/generated/renderer/render/stack/stack_transport_hash.h
"""
import hashlib
import os
import re
import sys

ROOTS = ["renderer/render/stack/stack_walk.cpp", "renderer/render/stack/stack_response.cpp",
         "renderer/render/spatial/stack_profiles.cpp"]
INCLUDE = re.compile(r'^[ \t]*#[ \t]*include[ \t]+"((?:renderer|materials)/[^"]+)"', re.M)


def closure(root):
    seen, todo = [], list(ROOTS)
    while todo:
        f = todo.pop(0)
        if f in seen or not os.path.isfile(os.path.join(root, f)):
            continue
        seen.append(f)
        for inc in INCLUDE.findall(open(os.path.join(root, f), encoding="utf-8", errors="replace").read()):
            todo.append(inc)
            if inc.startswith(("renderer/render/", "materials/")) and inc.endswith(".h"):
                todo.append(inc[:-2] + ".cpp")
    return sorted(seen)


def key(root, files, changed=None):
    text = ""
    for f in files:
        data = open(os.path.join(root, f), "rb").read()
        if f == changed:
            data += b"\n"
        text += f"{f}:{hashlib.sha256(data).hexdigest()};"
    return hashlib.sha256(text.encode()).hexdigest()


def main():
    root, header = sys.argv[1], sys.argv[2]
    text = open(header).read()
    built_hash = re.search(r'OFL_STACK_TRANSPORT_HASH "([0-9a-f]+)"', text).group(1)
    built_files = sorted(re.search(r"// Hashed: (.*)", text).group(1).strip().split(";"))
    files = closure(root)
    problems = []
    if built_files != files:
        problems.append("the build hashed " + ", ".join(sorted(set(built_files) ^ set(files))) +
                        " differently from the include closure")
    if key(root, files) != built_hash:
        problems.append("the compiled-in key is not the hash of the files' current contents (reconfigure?)")
    for f in files:
        if key(root, files, changed=f) == built_hash:
            problems.append(f"a change to {f} would not change the key")
    for p in problems:
        print(p)
    print(f"cache key: {len(files)} files, every one of them changes it" if not problems else
          f"{len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
