#!/usr/bin/env python3
"""Functions longer than a limit in C++ sources: the team's rule is <= 80 lines.

    python3 scripts/long_functions.py [--limit 80] [--headers] [PATH ...]

PATH is a file or a folder (default: the repository root, the folder above
this script's).  Folders are searched for *.cpp files (and *.hpp with
--headers); folders named build* and hidden folders are skipped.  Every
function over the limit is printed as

    path:line name length

with line the line of the function's name and length the lines from that
line to the closing brace, both included; the exit status is 1 when one was
found, 0 when none.

How it finds functions: comments, string and character literals and
preprocessor lines are blanked first; then braces are matched.  A brace at
file, namespace or class scope opens a function body when the text before it
(since the last ';', '{' or '}') has a parenthesis and is not a type,
namespace or '= {...}' initialiser; a constructor's brace-initialised
members ('x_{1}' after ') :') are not bodies.  Everything inside a body
(lambdas, local classes) counts towards that function.  It is a scanner, not
a parser: macros that hide braces fool it.
"""
import argparse
import os
import re
import sys

SCOPE_WORDS = ("namespace", "class", "struct", "union", "enum", "extern")
BODY_SUFFIXES = ("const", "noexcept", "override", "final", "mutable", "try")


def blank(text):
    """The text with comments, literals and preprocessor lines as spaces (newlines kept)."""
    out = list(text)
    i, n = 0, len(text)
    line_start = True

    def wipe(a, b):
        for k in range(a, b):
            if out[k] != "\n":
                out[k] = " "

    while i < n:
        c = text[i]
        if c == "\n":
            line_start = True
            i += 1
            continue
        if line_start and c in " \t":
            i += 1
            continue
        if line_start and c == "#":
            j = i
            while j < n and not (text[j] == "\n" and text[j - 1] != "\\"):
                j += 1
            wipe(i, j)
            i = j
            continue
        line_start = False
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            wipe(i, j)
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            wipe(i, j)
            i = j
        elif c == "R" and text.startswith('R"', i) and raw_prefix_ok(text, i):
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            if not m:
                i += 1
                continue
            end = text.find(")" + m.group(1) + '"', i + m.end())
            end = n if end < 0 else end + len(m.group(1)) + 2
            wipe(i, end)
            i = end
        elif c == '"' or (c == "'" and not is_digit_separator(text, i)):
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            wipe(i, min(j + 1, n))
            i = j + 1
        else:
            i += 1
    return "".join(out)


def raw_prefix_ok(text, i):
    """Whether the R at i starts a raw string literal (alone or after u8, u, U, L)."""
    j = i
    while j > 0 and (text[j - 1].isalnum() or text[j - 1] == "_"):
        j -= 1
    return text[j:i] in ("", "u8", "u", "U", "L")


def is_digit_separator(text, i):
    """Whether the quote at i is inside a number (1'000'000), not a character literal."""
    j = i
    while j > 0 and (text[j - 1].isalnum() or text[j - 1] in "_'."):
        j -= 1
    return j < i and text[j].isdigit()


def header_kind(header):
    """'function', 'scope' or 'other' for the text before a brace outside any function."""
    h = " ".join(header.split())
    first = re.match(r"(template\s*<.*?>\s*)?(\w+)", h)
    word = first.group(2) if first else ""
    if word in SCOPE_WORDS or re.match(r"^(\w+\s+)?(class|struct|union|enum)\b", h):
        if "(" not in h or word in ("namespace", "extern", "class", "struct", "union", "enum"):
            return "scope"
    if "(" not in h:
        return "scope" if h == "" else "other"
    if "operator" not in h and re.search(r"(?<![=!<>])=(?!=)", strip_parens(h)):
        return "other"
    if is_member_brace_init(h):
        return "init"
    return "function"


def strip_parens(h):
    """The text with every parenthesised or angle-bracketed part removed."""
    out, depth = [], 0
    for ch in h:
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth -= 1
        elif depth == 0:
            out.append(ch)
    return "".join(out)


def is_member_brace_init(h):
    """Whether the brace follows a member name in a constructor's initialiser list."""
    tail = re.search(r"(\w+)\s*$", h)
    if not tail or tail.group(1) in BODY_SUFFIXES:
        return False
    close = h.rfind(")")
    after = strip_parens(h[h.find("("):]) if "(" in h else ""
    return close >= 0 and re.search(r"(?<!:):(?!:)", after) is not None


def function_name(header):
    """The name before the first top-level parenthesis of a function header."""
    h = " ".join(header.split())
    m = re.search(r"((?:[\w~]+::)*(?:operator\s*[^\s(]+|~?\w+))\s*\($", h[:first_paren(h) + 1])
    if not m:
        return h[:40]
    if m.group(1) in ("TEST", "TEST_F", "TEST_P"):  # GoogleTest: the suite and test names
        args = re.match(r"\s*\(([^)]*)\)", h[first_paren(h):])
        return m.group(1) + "(" + (" ".join(args.group(1).split()) if args else "") + ")"
    return m.group(1)


def first_paren(h):
    """Index of the first '(' that is not inside template brackets, or -1."""
    angle = 0
    for k, ch in enumerate(h):
        if ch == "<":
            angle += 1
        elif ch == ">" and angle:
            angle -= 1
        elif ch == "(" and (angle == 0 or "operator" in h[:k]):
            return k
    return -1


def scan(path):
    """(line, name, length) of every function in a file."""
    with open(path, encoding="utf-8", errors="replace") as f:
        text = blank(f.read())
    found = []
    stack = []  # kinds of the open braces
    header_start = 0
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        in_function = any(kind in ("function", "other") for kind, _ in stack)
        if c in ";{}" and not in_function and c != "{":
            header_start = i + 1
        if c == "{":
            if in_function:
                stack.append(("block", 0))
            else:
                header = text[header_start:i]
                kind = header_kind(header)
                if kind == "init":
                    i = matching_brace(text, i) + 1
                    continue
                stack.append((kind, i))
                if kind != "function":
                    header_start = i + 1
        elif c == "}" and stack:
            kind, start = stack.pop()
            if kind == "function":
                header = text[header_start:start]
                paren = header_start + first_paren(header)
                name_line = text.count("\n", 0, paren) + 1
                end_line = text.count("\n", 0, i) + 1
                found.append((name_line, function_name(header), end_line - name_line + 1))
            if not any(k in ("function", "other") for k, _ in stack):
                header_start = i + 1
        i += 1
    return found


def matching_brace(text, i):
    """Index of the brace closing the one at i."""
    depth = 0
    for k in range(i, len(text)):
        if text[k] == "{":
            depth += 1
        elif text[k] == "}":
            depth -= 1
            if depth == 0:
                return k
    return len(text) - 1


def sources(paths, headers):
    """The C++ files under the given files and folders, sorted."""
    suffixes = (".cpp", ".hpp") if headers else (".cpp",)
    for p in paths:
        if os.path.isfile(p):
            yield p
            continue
        for root, dirs, files in os.walk(p):
            dirs[:] = sorted(d for d in dirs if not d.startswith((".", "build")))
            for name in sorted(files):
                if name.endswith(suffixes):
                    yield os.path.join(root, name)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("paths", nargs="*")
    parser.add_argument("--limit", type=int, default=80)
    parser.add_argument("--headers", action="store_true", help="also scan *.hpp files")
    args = parser.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    paths = args.paths or [os.path.relpath(root)]
    over = 0
    for path in sources(paths, args.headers):
        for line, name, length in scan(path):
            if length > args.limit:
                print(f"{os.path.normpath(path)}:{line} {name} {length}")
                over += 1
    return 1 if over else 0


if __name__ == "__main__":
    sys.exit(main())
