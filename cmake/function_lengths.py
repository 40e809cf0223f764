#!/usr/bin/env python3
"""Lists the functions in C++ headers longer than a limit (docs/design_notes.md: "no function over 60
lines"). A function's length is its lines from the first line of its signature to its closing brace,
comments and blank lines included. Lambdas and local classes count towards the function around them.
Usage: function_lengths.py LIMIT DIR... ; exit code 1 when one is longer, listing it as path:line: name N lines."""
import re
import sys
from pathlib import Path

CONTROL = re.compile(r"^\s*(if|for|while|switch|catch|do|else)\b")
CLASS = re.compile(r"\b(struct|class|union|enum)\b\s*[\w:]*\s*(final)?\s*(:[^{]*)?$")


def strip(text):
    """Comments, string and character literals blanked out, newlines kept."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i)); i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("".join(ch if ch == "\n" else " " for ch in text[i:j])); i = j
        elif c == '"' and text.startswith('R"', i - 1):
            m = re.match(r'"([^(]*)\(', text[i:])
            end = text.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append("".join(ch if ch == "\n" else " " for ch in text[i:j])); i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(c + " " * (j - i - 1) + c if j < n else text[i:]); i = j + 1
        else:
            out.append(c); i += 1
    return "".join(out)


def without_templates(head):
    head = head.strip()
    while head.startswith("template"):
        depth, i = 0, head.find("<")
        if i < 0:
            break
        for j in range(i, len(head)):
            depth += {"<": 1, ">": -1}.get(head[j], 0)
            if depth == 0:
                head = head[j + 1:].strip()
                break
        else:
            break
    return head


def functions(path):
    text = strip(path.read_text(errors="replace"))
    text = re.sub(r"(?m)^[ \t]*#.*$", lambda m: " " * len(m.group(0)), text)  # preprocessor lines
    scopes = []  # (kind, name, start line)
    head_start = 0
    line = 1
    parens = 0  # braces inside parentheses (a default argument's {}, a lambda in a call) are no bodies
    for i, c in enumerate(text):
        if c == "\n":
            line += 1
        if c in "()":
            parens += 1 if c == "(" else -1
            continue
        if parens > 0:
            if c == "{":
                scopes.append(("other", "", line))
            elif c == "}" and scopes:
                scopes.pop()
            continue
        if c in ";{}":
            if c == "{":
                head = text[head_start:i]
                outer = scopes[-1][0] if scopes else "namespace"
                h = without_templates(head.replace("\n", " "))
                if outer in ("function", "other"):
                    kind = "other"
                elif h.startswith("namespace") or h.startswith('extern "C"') or h == "":
                    kind = "namespace" if h.startswith("namespace") or h.startswith("extern") else "other"
                elif CLASS.search(h) and "(" not in h.split("{")[0]:
                    kind = "class"
                elif "(" in h and not CONTROL.match(h) and "=" not in h.split("(")[0]:
                    kind = "function"
                else:
                    kind = "other"
                # the signature's first line: skip the blank lines before it
                lead = len(head) - len(head.lstrip())
                first = line - head[lead:].count("\n")
                name = re.findall(r"([~\w:<>]+)\s*\(", h)
                scopes.append((kind, name[0] if name else h[:40], first))
            elif c == "}" and scopes:
                kind, name, first = scopes.pop()
                if kind == "function":
                    yield name, first, line - first + 1
            head_start = i + 1
    return


def main():
    limit = int(sys.argv[1])
    long = []
    for root in sys.argv[2:]:
        for path in sorted(Path(root).rglob("*.hpp")):
            for name, first, length in functions(path):
                if length > limit:
                    long.append(f"{path}:{first}: {name} {length} lines")
    print("\n".join(long) if long else f"no function over {limit} lines")
    return 1 if long else 0


if __name__ == "__main__":
    sys.exit(main())
