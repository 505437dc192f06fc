#!/usr/bin/env python3
"""optional_dependencies_compile.py BUILD_DIR SOURCE... — compiles (syntax only) each SOURCE as a
build without OpenImageIO and Embree sees it (-DOBSCURA_WITH_OPENIMAGEIO=OFF and no Embree: the
bundle of tools/gpu), with the flags of BUILD_DIR/compile_commands.json less the two defines. The
default build never compiles the #ifdef branches that such a build takes; this keeps them honest
without a second build. Exit status 1 names the source that failed."""
import json
import shlex
import subprocess
import sys

DROPPED_DEFINES = {"-DOBSCURA_HAVE_OPENIMAGEIO", "-DOBSCURA_HAVE_EMBREE"}


def syntax_only(command):
    """The compile command with its output, dependency files and the two defines left out."""
    args, out, skip = shlex.split(command), [], False
    for a in args:
        if skip:
            skip = False
        elif a in ("-o", "-MT", "-MF", "-MQ"):
            skip = True
        elif a in ("-c", "-MD", "-MMD") or a in DROPPED_DEFINES:
            pass
        else:
            out.append(a)
    return out + ["-fsyntax-only"]


def main():
    build_dir, sources = sys.argv[1], sys.argv[2:]
    with open(f"{build_dir}/compile_commands.json") as f:
        entries = json.load(f)
    for source in sources:
        matches = [e for e in entries if e["file"].endswith("/" + source)]
        if not matches:
            sys.exit(f"{source}: not in {build_dir}/compile_commands.json")
        entry = matches[0]
        command = entry["command"] if "command" in entry else shlex.join(entry["arguments"])
        if not any(d in command for d in DROPPED_DEFINES):
            sys.exit(f"{source}: its compile command defines neither of {sorted(DROPPED_DEFINES)}: nothing to check")
        result = subprocess.run(syntax_only(command), cwd=entry["directory"], capture_output=True, text=True)
        if result.returncode != 0:
            sys.exit(f"{source} does not compile without OpenImageIO and Embree:\n{result.stderr}")
        print(f"{source}: compiles without OpenImageIO and Embree")


if __name__ == "__main__":
    main()
