#!/usr/bin/python3
"""Size limits for the tracked C++ and Python sources (src/ apps/ python/ fuzz/ bench/ tests/,
and for Python also scripts/ and tools/).

  * no file over 600 lines;
  * no function body (C++: from its '{' line to its '}' line; Python: from its 'def' line to
    its last line) over 80 lines, unless a comment reaching into the 3 lines above the
    function's signature (a run of '//' or '#' lines counts as one comment) says
    `long-function: <reason>`.

tools/blender/ is left out until its add-on is split into a package of small modules (issue
#29); today its largest function is 167 lines.

Usage: /usr/bin/python3 scripts/check_sizes.py [--only PATH...] [--list]
  --only PATH...  check only the files at or under these paths (repo-relative);
  --list          also print every function's length (longest first) to stdout.
Exit 1 with one line per offender:
  path: N lines (max 600)
  path:line: function NAME is N lines (max 80)

Functions are found with a brace-matching heuristic, not a parser: comments, string, raw
string and character literals are blanked first; '#else'/'#elif' branches are skipped so
each conditional keeps one brace structure; a '{' at namespace or class scope opens a
function when the text before it has a parameter list '(...)' after a name. Lambdas and
local classes inside a function count toward it; namespace, class, struct and union
bodies are scopes (their member functions are checked), enum bodies and brace
initializers of variables are data.

Test files (tests/ and *_test.cpp) get the file rule but the function rule only for their
helpers: a gtest case body (TEST, TEST_F, TEST_P, TYPED_TEST) is a script of checks that
reads top to bottom, and cutting it into helpers would hide what each case asserts. The same
holds for Python test files (test_*.py, or under a tests/ folder) and their test_* functions.

Python functions (and methods, and functions inside functions, each counted on its own) are
found with the ast module.
"""

import argparse
import ast
import os
import re
import subprocess
import sys

MAX_FILE_LINES = 600
MAX_FUNCTION_LINES = 80
ROOTS = ("src/", "apps/", "python/", "fuzz/", "bench/", "tests/")
PYTHON_ROOTS = ROOTS + ("scripts/", "tools/")
PYTHON_LEFT_OUT = ("tools/blender/",)
MARKER = re.compile(r"long-function:\s*\S")
TEST_MACROS = {"TEST", "TEST_F", "TEST_P", "TYPED_TEST", "TYPED_TEST_P"}
# Words that take a parenthesised argument but are not a function's name.
NOT_NAMES = {
    "if", "while", "for", "switch", "return", "sizeof", "alignof", "alignas", "decltype",
    "noexcept", "throw", "requires", "static_assert", "typeid", "catch", "explicit",
    "__attribute__", "__declspec", "asm", "co_return", "co_await", "co_yield", "new", "delete",
}
CLASS_KEYS = {"class", "struct", "union"}
ACCESS = {"public", "private", "protected"}


def blank(text):
    """Returns (code, comments): code with comments and literals replaced by spaces (newlines
    kept, so line numbers hold) and preprocessor lines removed; comments as a list of
    (first_line, last_line, text) with runs of '//' lines merged."""
    out = []
    comments = []
    i, n, line = 0, len(text), 1
    at_line_start = True

    def keep_newlines(s):
        return "".join("\n" if c == "\n" else " " for c in s)

    while i < n:
        c = text[i]
        if c == "\n":
            out.append(c)
            line += 1
            i += 1
            at_line_start = True
            continue
        if at_line_start and c in " \t":
            out.append(c)
            i += 1
            continue
        if at_line_start and c == "#":
            i, line = skip_directive(text, i, line, out)
            continue
        at_line_start = False
        if text.startswith("//", i):
            end = text.find("\n", i)
            end = n if end < 0 else end
            body = text[i:end]
            if comments and comments[-1][1] == line - 1 and comments[-1][3]:
                first, _, prev, _ = comments[-1]
                comments[-1] = (first, line, prev + "\n" + body, True)
            else:
                comments.append((line, line, body, True))
            out.append(" " * (end - i))
            i = end
            continue
        if text.startswith("/*", i):
            end = text.find("*/", i + 2)
            end = n if end < 0 else end + 2
            body = text[i:end]
            comments.append((line, line + body.count("\n"), body, False))
            out.append(keep_newlines(body))
            line += body.count("\n")
            i = end
            continue
        if c == '"':
            end = string_end(text, i)
            body = text[i:end]
            out.append('""' + keep_newlines(body[2:]))
            line += body.count("\n")
            i = end
            continue
        if c == "'":
            if is_digit_separator(text, i):
                out.append(c)
                i += 1
                continue
            end = i + 1
            while end < n and text[end] != "'" and text[end] != "\n":
                end += 2 if text[end] == "\\" else 1
            end += 1
            out.append("0" + " " * (end - i - 1))
            i = end
            continue
        out.append(c)
        i += 1
    return "".join(out), [(a, b, t) for a, b, t, _ in comments]


def string_end(text, i):
    """The index just past the string literal opening at text[i] == '"' (raw strings too)."""
    n = len(text)
    raw = re.search(r"(?:u8|u|U|L)?R$", text[max(0, i - 3):i])
    before = i - len(raw.group(0)) - 1 if raw else -1
    if raw and (before < 0 or not re.match(r"\w", text[before])):
        delim_end = text.find("(", i)
        close = ")" + text[i + 1:delim_end] + '"'
        end = text.find(close, delim_end)
        return n if end < 0 else end + len(close)
    end = i + 1
    while end < n and text[end] != '"' and text[end] != "\n":
        end += 2 if text[end] == "\\" else 1
    return end + 1


def is_digit_separator(text, i):
    """True for the quote in 1'000'000 (a quote inside a token that starts with a digit)."""
    j = i
    while j > 0 and (text[j - 1].isalnum() or text[j - 1] in "_'."):
        j -= 1
    return j < i and text[j].isdigit()


def skip_directive(text, i, line, out):
    """Blanks one preprocessor line (with continuations); at '#else'/'#elif' also blanks
    everything up to the matching '#endif'. Returns the new (index, line)."""
    def line_end(k):
        while True:
            e = text.find("\n", k)
            if e < 0:
                return len(text)
            if e > 0 and text[e - 1] == "\\":
                k = e + 1
                continue
            return e

    word = re.match(r"#\s*(\w*)", text[i:]).group(1)
    end = line_end(i)
    if word in ("else", "elif"):
        depth = 0
        k = end
        while k < len(text):
            m = re.compile(r"^[ \t]*#\s*(\w+)", re.M).search(text, k)
            if not m:
                k = len(text)
                break
            w = m.group(1)
            if w.startswith("if"):
                depth += 1
            elif w == "endif":
                if depth == 0:
                    k = line_end(m.start())
                    break
                depth -= 1
            k = m.end()
        end = k
    body = text[i:end]
    out.append("".join("\n" if ch == "\n" else " " for ch in body))
    return end, line + body.count("\n")


TOKEN = re.compile(r"\s+|([A-Za-z_]\w*|\d[\w.']*|::|->|\"\"|.)", re.S)


def tokenize(code):
    tokens = []  # (text, line)
    line = 1
    for m in TOKEN.finditer(code):
        if m.group(1) is None:
            line += m.group(0).count("\n")
        else:
            tokens.append((m.group(1), line))
    return tokens


def is_ident(t):
    return bool(re.match(r"[A-Za-z_]\w*$", t))


def match_close(tokens, i, open_t, close_t):
    depth = 0
    for j in range(i, len(tokens)):
        t = tokens[j][0]
        if t == open_t:
            depth += 1
        elif t == close_t:
            depth -= 1
            if depth == 0:
                return j
    return len(tokens) - 1


def strip_prefix(header):
    """Drops leading 'template <...>' lists and [[attributes]] from a header token list."""
    changed = True
    while changed and header:
        changed = False
        if header[0][0] == "template" and len(header) > 1 and header[1][0] == "<":
            depth, j = 0, 1
            while j < len(header):
                t = header[j][0]
                depth += (t == "<") - (t == ">")
                if t == "(":  # skip '(...)' in template args, which may hold '>'
                    j = match_close(header, j, "(", ")")
                elif depth == 0:
                    break
                j += 1
            header = header[j + 1:]
            changed = True
        elif len(header) > 1 and header[0][0] == "[" and header[1][0] == "[":
            header = header[match_close(header, 0, "[", "]") + 1:]
            changed = True
    return header


def function_name(header):
    """The function's name and line if the header declares a function definition, else None.
    A function header has a top-level '(...)' right after a name (or after 'operator@')."""
    depth = 0
    for k, (t, _) in enumerate(header):
        if t in "([":
            if depth == 0 and t == "(":
                name = name_before(header, k)
                if name:
                    return name
            depth += 1
        elif t in ")]":
            depth -= 1
        elif t == "=" and depth == 0 and not any(h[0] == "operator" for h in header[:k]):
            return None  # a variable's initializer (e.g. a lambda), not a function
    return None


def name_before(header, k):
    """Name (qualified) ending just before header[k] == '(' or None."""
    j = k - 1
    if j < 0:
        return None
    # operator@ : walk back to the 'operator' keyword.
    for back in range(j, max(-1, j - 4), -1):
        if header[back][0] == "operator":
            if header[back + 1][0] == "(" and back + 1 == k:
                return None  # 'operator(' : the name is 'operator()', params come next
            op = "".join(t for t, _ in header[back + 1:k])
            return qualify(header, back, "operator" + op)
    t = header[j][0]
    if not is_ident(t) or t in NOT_NAMES:
        return None
    qualified = j > 0 and header[j - 1][0] in ("::", "~")
    if re.match(r"[A-Z_][A-Z0-9_]+$", t) and not qualified:  # a macro: TEST(Suite, Case)
        close = match_close(header, k, "(", ")")
        args = " ".join(x for x, _ in header[k + 1:close]).replace(" ,", ",")
        return (f"{t}({args})", header[j][1])
    return qualify(header, j, t)


def qualify(header, j, name):
    """Prepends 'Scope::' qualifiers (and '~') found before header[j]."""
    line = header[j][1]
    while j >= 1:
        prev = header[j - 1][0]
        if prev == "~":
            name = "~" + name
            j -= 1
        elif prev == "::" and j >= 2:
            q = j - 2
            if header[q][0] == ">":  # Foo<T>::bar
                depth = 0
                while q >= 0:
                    depth += (header[q][0] == ">") - (header[q][0] == "<")
                    if depth == 0:
                        break
                    q -= 1
                q -= 1
            if q < 0 or not is_ident(header[q][0]):
                break
            name = header[q][0] + "::" + name
            j = q
        else:
            break
    return (name, line)


def classify(header):
    """'function' (with name), 'scope' or 'data' for the '{' that follows header."""
    header = strip_prefix(header)
    words = [t for t, _ in header]
    if "namespace" in words or words == ["extern", '""'] or words == ["extern"]:
        return "scope", None
    named = function_name(header)
    if named:
        return "function", named
    if any(w in CLASS_KEYS for w in words) and "=" not in words:
        return "scope", None
    return "data", None


def scan_functions(tokens):
    """Yields (name, name_line, header_line, open_line, close_line, is_test_case)."""
    header = []
    i, n = 0, len(tokens)
    while i < n:
        t, line = tokens[i]
        if t == "{":
            paren = sum((h[0] in "([") - (h[0] in ")]") for h in header)
            in_init_list = init_list_started(header)
            if paren > 0 or (in_init_list and header and (is_ident(header[-1][0]) or
                                                          header[-1][0] == ">")):
                j = match_close(tokens, i, "{", "}")  # braced argument or member initializer
                header.append(("{}", line))
                i = j + 1
                continue
            kind, named = classify(header)
            if kind == "scope":
                header = []
                i += 1
                continue
            j = match_close(tokens, i, "{", "}")
            if kind == "function":
                name, name_line = named
                start = header[0][1]
                macro = name.split("(")[0]
                yield name, name_line, start, line, tokens[j][1], macro in TEST_MACROS
                header = []
            else:
                header.append(("{}", line))
            i = j + 1
            continue
        if t in (";", "}"):
            header = []
        elif t == ":" and len(header) == 1 and header[0][0] in ACCESS:
            header = []
        else:
            header.append((t, line))
        i += 1


def init_list_started(header):
    """True once a constructor's ') :' has been seen, so 'member{...}' is an initializer."""
    depth = 0
    for k, (t, _) in enumerate(header):
        if t in "([":
            depth += 1
        elif t in ")]":
            depth -= 1
        elif t == ":" and depth == 0 and k > 0 and header[k - 1][0] == ")":
            return function_name(strip_prefix(header[:k])) is not None
    return False


def marked(comments, start_line):
    for first, last, body in comments:
        if last >= start_line - 3 and first < start_line and MARKER.search(body):
            return True
    return False


def read_with_file_limit(path):
    """The file's text, and the problem of its length when it is over the file limit."""
    problems = []
    with open(path, encoding="utf-8", errors="replace") as f:
        text = f.read()
    lines = text.count("\n") + (0 if text.endswith("\n") or not text else 1)
    if lines > MAX_FILE_LINES:
        problems.append((path, 0, f"{path}: {lines} lines (max {MAX_FILE_LINES})"))
    return text, problems


def check_file(path, lister):
    text, problems = read_with_file_limit(path)
    is_test = path.startswith("tests/") or path.endswith("_test.cpp")
    code, comments = blank(text)
    for name, name_line, start, open_line, close_line, test_case in scan_functions(
            tokenize(code)):
        length = close_line - open_line + 1
        lister.append((length, f"{path}:{name_line}: {name}"))
        if length <= MAX_FUNCTION_LINES or (is_test and test_case):
            continue
        if marked(comments, start) or marked(comments, name_line):
            continue
        problems.append((path, name_line, f"{path}:{name_line}: function {name} is {length} "
                                          f"lines (max {MAX_FUNCTION_LINES})"))
    return problems


def python_comments(text):
    """Runs of '#' comment lines as (first_line, last_line, text), like blank()'s comments."""
    comments = []
    for number, raw in enumerate(text.splitlines(), 1):
        stripped = raw.strip()
        if not stripped.startswith("#"):
            continue
        if comments and comments[-1][1] == number - 1:
            first, _, body = comments[-1]
            comments[-1] = (first, number, body + "\n" + stripped)
        else:
            comments.append((number, number, stripped))
    return comments


def check_python_file(path, lister):
    text, problems = read_with_file_limit(path)
    name = os.path.basename(path)
    is_test = name.startswith("test_") or "/tests/" in "/" + path
    comments = python_comments(text)
    for node in ast.walk(ast.parse(text, filename=path)):
        if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        length = node.end_lineno - node.lineno + 1
        lister.append((length, f"{path}:{node.lineno}: {node.name}"))
        if length <= MAX_FUNCTION_LINES or (is_test and node.name.startswith("test_")):
            continue
        start = min([node.lineno] + [d.lineno for d in node.decorator_list])
        if marked(comments, start):
            continue
        problems.append((path, node.lineno, f"{path}:{node.lineno}: function {node.name} is "
                                            f"{length} lines (max {MAX_FUNCTION_LINES})"))
    return problems


def tracked(patterns, roots, left_out=()):
    files = subprocess.run(["git", "ls-files"] + patterns, check=True, text=True,
                           capture_output=True).stdout.split()
    return [f for f in files if f.startswith(roots) and not f.startswith(left_out)]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="+", metavar="PATH", help="check only these paths")
    parser.add_argument("--list", action="store_true", help="print every function's length")
    args = parser.parse_args()
    os.chdir(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    files = tracked(["*.cpp", "*.h"], ROOTS) + tracked(["*.py"], PYTHON_ROOTS, PYTHON_LEFT_OUT)
    if args.only:
        wanted = [os.path.normpath(p) for p in args.only]
        files = [f for f in files if any(f == w or f.startswith(w.rstrip("/") + "/")
                                         for w in wanted)]
    problems, lister = [], []
    for path in sorted(files):
        check = check_python_file if path.endswith(".py") else check_file
        problems += check(path, lister)
    if args.list:
        for length, where in sorted(lister, key=lambda x: -x[0]):
            print(f"{length:5d} {where}")
    for _, _, message in sorted(problems):
        print(message)
    if problems:
        return 1
    python = sum(f.endswith(".py") for f in files)
    print(f"check_sizes: {len(files)} files ({len(files) - python} C++, {python} Python) within "
          f"{MAX_FILE_LINES} lines, "
          f"functions within {MAX_FUNCTION_LINES}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
