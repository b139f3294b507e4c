#!/usr/bin/env python3
"""Writes calibench(1) from the executable's own help, so that it never drifts.

help2man makes the page from `calibench --help` (NAME, SYNOPSIS, the command list); this script
adds a section per command from `calibench help <command>` (CLI11's help: a description, the usage
line, one entry per flag) as help2man's --include file.

    packaging/make_man.py build/calibench build/man/calibench.1
"""
import os
import re
import subprocess
import sys
from pathlib import Path


def roff(text: str, literal: bool = False) -> str:
    """Text as roff: backslashes escaped, the hyphens of flags (all of them when `literal`) as
    \\- so that they print and copy as the ASCII minus a shell needs."""
    text = text.replace("\\", "\\e")
    if literal:
        text = text.replace("-", "\\-")
    else:
        text = re.sub(r"(?<![\w-])--?[A-Za-z][\w-]*", lambda m: m.group(0).replace("-", "\\-"),
                      text)
    return "\\&" + text if text[:1] in (".", "'") else text


def help_text(exe: str, *args: str) -> str:
    return subprocess.run([exe, *args], check=True, capture_output=True, text=True).stdout


def command_section(exe: str, command: str) -> str:
    """One command's help as roff: its description, usage, then .TP per flag."""
    lines = help_text(exe, "help", command).splitlines()
    out, flags = [], []
    in_options = False
    for line in lines:
        if line.startswith("Options:") or line.startswith("Positionals:"):
            in_options = True
            continue
        if not in_options:
            if line.startswith("Usage:"):
                out += [".PP", ".B " + roff(line[len("Usage: "):])]
            elif line.strip():
                out.append(roff(line.strip()))
            continue
        match = re.match(r"^  (\S.*?)(?:\s{2,}(.*))?$", line)
        if match:  # "  -d,--dataset TEXT   description"
            flags.append([match.group(1), (match.group(2) or "").strip()])
        elif line.strip() and flags:  # the description of a long flag, on its own line
            flags[-1][1] = (flags[-1][1] + " " + line.strip()).strip()
    for spec, desc in flags:
        out += [".TP", "\\fB" + roff(spec, literal=True) + "\\fR", roff(desc)]
    return "\n".join(out)


def main() -> int:
    exe, page = sys.argv[1], Path(sys.argv[2])
    usage = help_text(exe, "--help")
    commands = re.findall(r"^  ([a-z][a-z-]+) ", usage.split("commands:", 1)[1], re.M)
    commands = [c for c in commands if c != "help"]
    include = page.with_suffix(".h2m")
    sections = ["[DESCRIPTION]",
                "Calibench calibrates the extrinsic pose between range sensors (3D LiDARs, 2D laser "
                "rangefinders) and cameras from small printed boards, says how well it knows it "
                "(1\\(*s per axis) and guides the capture. One executable with a command per task; "
                "`calibench help COMMAND' prints a command's flags, also listed below."]
    for command in commands:
        sections += [f"[COMMAND {command.upper()}]", command_section(exe, command)]
    sections += ["[FILES]",
                 ".TP", "\\fI/usr/share/calibench/assets\\fR",
                 "shaders, fonts and the report's scripts (\\fBcalibench \\-\\-version\\fR names the "
                 "folder in use; \\fBCALIBENCH_ASSETS\\fR overrides it)",
                 "[SEE ALSO]",
                 "The Python module: \\fBpython3 \\-c 'import calibench; help(calibench)'\\fR."]
    include.write_text("\n".join(sections) + "\n")
    version = help_text(exe, "--version").splitlines()[0].split()[-1]
    page.parent.mkdir(parents=True, exist_ok=True)
    subprocess.run(["help2man", "--no-info", "--locale=C.UTF-8", "--section=1",
                    f"--version-string={version}",
                    "--name=calibrate range sensors (LiDAR, 2D LRF) to cameras with printed boards",
                    f"--include={include}", f"--output={page}", exe], check=True,
                   env={**os.environ, "LC_ALL": "C.UTF-8"})
    return 0


if __name__ == "__main__":
    sys.exit(main())
