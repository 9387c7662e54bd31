"""Runs every fenced code block of the README and docs/ (issue 15: a newcomer
can trust what the pages show).

    doc_examples.py cpp OUT.cpp PAGE.md [PAGE.md ...]
        writes the pages' C++ blocks as one translation unit (the target
        doc_snippets builds it against the library): one function per page,
        each block in its own scope, #line pointing back at the page, every
        #include hoisted to the top. `doc_snippets PAGE` runs one page's blocks.
    doc_examples.py check --source DIR --build DIR --snippets EXE --cli-dir DIR
                          [--python-path DIR] PAGE.md [PAGE.md ...]
        runs or checks every block and exits 1 naming the page, the line and
        the reason of each failure.

What a block's info string (the words after the opening fence) means:
  cpp            statements, compiled by doc_snippets and run (no exception);
  python         run with the built module on PYTHONPATH; a page's python
                 blocks run in order in one interpreter, sharing names;
  console        `$ command` lines run by bash in a scratch folder with the
                 built `proxima` first on PATH; the lines after a command, up
                 to the next `$`, are its exact standard output;
  sh             every command run the same way (output not compared);
  json query     query lines, answered by `proxima query` (exit status 0);
  json answer    the exact answer lines of one of the page's earlier
                 `json query` blocks;
  output         the exact standard output of the page's previous cpp or
                 python block;
  ANY file=NAME  written to NAME in the scratch folder before the page runs.
The line just before a fence may instead say how the block is checked:
  <!-- quoted from: FILE [FILE ...] -->  the block's lines, each stripped of
      leading and trailing blanks, appear as consecutive lines of one of the
      files (paths from the source root), which other tests build and run;
  <!-- run by: FILE -->  FILE (a test script) exists and names this page;
  <!-- not run: REASON -->  only where running is impossible here (the
      tests themselves, installing packages, minutes-long benchmarks).
A block with none of these fails, and so does an indented code block (four
spaces after a blank line, outside a list): fence it and say how it runs.
The scratch folder holds build/release (the build under test), the source
tree's folders, and the page's file= blocks.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

MARKER = re.compile(r"^<!--\s*(quoted from|run by|not run):\s*(.*?)\s*-->$")
TIMEOUT = 120  # seconds per command; the whole check takes seconds


class Block:
    def __init__(self, page, line, info, body, marker):
        self.page, self.line, self.body, self.marker = page, line, body, marker
        words = info.split()
        self.lang = words[0] if words else ""
        self.attrs = words[1:]
        self.file = next((w[5:] for w in words if w.startswith("file=")), None)

    def where(self):
        return f"{self.page}, line {self.line}"


def parse(path, label):
    """The fenced blocks of a page, and the problems of its layout."""
    lines = open(path, encoding="utf-8").read().splitlines()
    blocks, problems = [], []
    start = info = None
    body = []
    last_text = ""  # the last non-blank line outside code blocks
    previous_blank = True
    for number, line in enumerate(lines, 1):
        stripped = line.strip()
        if start is None and stripped.startswith("```"):
            start, info, body = number, stripped[3:].strip(), []
            marker = MARKER.match(last_text)
            marker = (marker.group(1), marker.group(2)) if marker else None
            continue
        if start is not None:
            if stripped == "```":
                blocks.append(Block(label, start, info, body, marker))
                start = None
                last_text, previous_blank = "```", False
            else:
                body.append(line)
            continue
        indented = line.startswith("    ") or line.startswith("\t")
        in_list = re.match(r"^\s*([-*+]|\d+\.)\s", last_text) is not None or last_text.startswith("  ")
        if indented and stripped and previous_blank and not in_list:
            problems.append(f"{label}, line {number}: indented code block (fence it and say how it runs): {stripped}")
        if stripped:
            if not (indented and previous_blank and not in_list):
                last_text = line
        previous_blank = not stripped
    if start is not None:
        problems.append(f"{label}, line {start}: code block never closed")
    return blocks, problems


def page_function(label):
    return "page_" + re.sub(r"[^A-Za-z0-9]", "_", label)


def write_cpp(out, pages):
    includes, functions, names = [], [], []
    for path in pages:
        label = os.path.relpath(path, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
        blocks, _ = parse(path, label)
        code = [b for b in blocks if b.lang == "cpp" and b.marker is None]
        if not code:
            continue
        name = page_function(label)
        names.append((label, name))
        text = [f"void {name}() {{"]
        for b in code:
            text.append(f'  begin_block("{b.where()}");')
            text.append("  {")
            text.append(f'#line {b.line + 1} "{os.path.abspath(path)}"')
            for line in b.body:
                if line.lstrip().startswith("#include"):
                    includes.append(line.strip())
                    text.append("")
                else:
                    text.append(line)
            text.append("  }")
        text.append("}")
        functions.append("\n".join(text))
    # The driver's own includes come after the pages' functions, so that a
    # block that forgets an include of its own fails to compile (unless
    # another page's block includes it: one translation unit for all pages).
    head = sorted(set(includes)) + ["", "namespace {", "void begin_block(const char* where);"]
    driver = functions
    driver += ["}  // namespace", "", "#include <cstdio>", "#include <cstring>", "#include <exception>",
               "#include <iostream>", "", "namespace {",
               "void begin_block(const char* where) {",
               "  std::cout.flush();",
               "  std::fflush(stdout);",
               '  std::printf("@@block %s\\n", where);',
               "  std::fflush(stdout);",
               "}",
               "}  // namespace", "", "int main(int argc, char** argv) {",
               "  try {"]
    for label, name in names:
        driver.append(f'    if (argc < 2 || std::strcmp(argv[1], "{label}") == 0) {name}();')
    driver += ["  } catch (const std::exception& e) {",
               "    std::cout.flush();",
               '    std::fprintf(stderr, "exception: %s\\n", e.what());',
               "    return 1;",
               "  }",
               "  std::cout.flush();",
               "  return 0;",
               "}"]
    content = "// Generated by tests/doc_examples.py from the pages' cpp blocks: do not edit.\n" + \
        "\n".join(head) + "\n\n" + "\n".join(driver) + "\n"
    if not os.path.exists(out) or open(out, encoding="utf-8").read() != content:
        with open(out, "w", encoding="utf-8") as f:
            f.write(content)


def contains(haystack, needle):
    return any(haystack[i:i + len(needle)] == needle for i in range(len(haystack) - len(needle) + 1))


def sections(stdout):
    """Splits a run's output at the @@block lines: {where: text}."""
    out, current = {}, None
    for line in stdout.splitlines(keepends=True):
        if line.startswith("@@block "):
            current = line[len("@@block "):].strip()
            out[current] = ""
        elif current is not None:
            out[current] += line
    return out


PYTHON_DRIVER = r"""
import json, sys
blocks = json.load(sys.stdin)
namespace = {"__name__": "__main__"}
for where, source, first_line in blocks:
    print("@@block " + where, flush=True)
    code = compile("\n" * (first_line - 1) + source, where.split(",")[0], "exec")
    exec(code, namespace)
    sys.stdout.flush()
"""


def commands(body):
    """The commands of an sh block: `\\`-continued lines joined, comments dropped."""
    out, pending = [], ""
    for line in body:
        if line.rstrip().endswith("\\"):
            pending += line.rstrip()[:-1] + " "
            continue
        line = pending + line
        pending = ""
        if line.strip() and not line.strip().startswith("#"):
            out.append(line.strip())
    return out


def console_steps(body):
    """(command, expected output) pairs of a console block."""
    steps, command, expected, continued = [], None, [], False
    for line in body:
        if continued:
            command += " " + line.strip().rstrip("\\")
            continued = line.rstrip().endswith("\\")
        elif line.startswith("$ "):
            if command is not None:
                steps.append((command, expected))
            command, expected = line[2:].strip().rstrip("\\"), []
            continued = line.rstrip().endswith("\\")
        elif command is not None:
            expected.append(line)
    if command is not None:
        steps.append((command, expected))
    return steps


class Checker:
    def __init__(self, args):
        self.args = args
        self.failures, self.counts = [], {}
        self.env = dict(os.environ)
        self.env["PATH"] = os.path.abspath(args.cli_dir) + os.pathsep + self.env.get("PATH", "")
        self.env["PYTHONDONTWRITEBYTECODE"] = "1"
        if args.python_path:
            self.env["PYTHONPATH"] = os.path.abspath(args.python_path)

    def fail(self, block, message):
        self.failures.append(f"{block.where()}: {message}")

    def count(self, what):
        self.counts[what] = self.counts.get(what, 0) + 1

    def scratch(self):
        work = tempfile.mkdtemp(prefix="proxima-docs.")
        for entry in os.listdir(self.args.source):
            if entry not in ("build", ".git"):
                os.symlink(os.path.join(self.args.source, entry), os.path.join(work, entry))
        os.makedirs(os.path.join(work, "build"))
        os.symlink(os.path.abspath(self.args.build), os.path.join(work, "build", "release"))
        return work

    def run(self, command, work, stdin=None):
        return subprocess.run(["bash", "-c", "set -eo pipefail\n" + command], cwd=work, env=self.env, input=stdin,
                              capture_output=True, text=True, timeout=TIMEOUT)

    def check_page(self, path, label):
        blocks, problems = parse(path, label)
        self.failures += problems
        work = self.scratch()
        try:
            self.check_blocks(blocks, work)
        finally:
            shutil.rmtree(work, ignore_errors=True)

    def check_blocks(self, blocks, work):
        for b in blocks:
            if b.file:
                with open(os.path.join(work, b.file), "w", encoding="utf-8") as f:
                    f.write("\n".join(b.body) + "\n")
        outputs = {}
        label = blocks[0].page if blocks else ""
        if any(b.lang == "cpp" and b.marker is None for b in blocks):
            r = subprocess.run([os.path.abspath(self.args.snippets), label], cwd=work, env=self.env,
                               capture_output=True, text=True, timeout=TIMEOUT)
            outputs.update(sections(r.stdout))
            if r.returncode != 0:
                ran = list(sections(r.stdout))
                where = ran[-1] if ran else label
                self.failures.append(f"{where}: the C++ block failed (exit {r.returncode}): {r.stderr.strip()}")
        python = [b for b in blocks if b.lang == "python" and b.marker is None]
        if python and self.args.python_path:
            payload = json.dumps([(b.where(), "\n".join(b.body) + "\n", b.line + 1) for b in python])
            r = subprocess.run([sys.executable, "-c", PYTHON_DRIVER], cwd=work, env=self.env, input=payload,
                               capture_output=True, text=True, timeout=TIMEOUT)
            outputs.update(sections(r.stdout))
            if r.returncode != 0:
                ran = list(sections(r.stdout))
                where = ran[-1] if ran else label
                self.failures.append(f"{where}: the Python block failed: {r.stderr.strip()}")
        previous, answers = None, []
        for b in blocks:
            if b.marker is not None:
                self.check_marker(b)
            elif b.lang == "cpp":
                self.count("cpp blocks run")
                previous = b
            elif b.lang == "python":
                if self.args.python_path:
                    self.count("python blocks run")
                else:
                    self.count("python blocks skipped (no Python module in this build)")
                previous = b
            elif b.lang == "output":
                self.check_output(b, previous, outputs)
            elif b.lang == "console":
                self.check_console(b, work)
            elif b.lang == "sh":
                for command in commands(b.body):
                    r = self.run(command, work)
                    if r.returncode != 0:
                        self.fail(b, f"`{command}` exited {r.returncode}: {r.stderr.strip()[-2000:]}")
                self.count("sh blocks run")
            elif b.lang == "json" and "query" in b.attrs:
                answers.append(self.check_query(b, work))
            elif b.lang == "json" and "answer" in b.attrs:
                self.count("json answers compared")
                if b.body not in answers:
                    self.fail(b, "not the answer of an earlier json query; they are\n    " +
                              "\n    ".join(line for answer in answers for line in answer))
            elif b.file:
                self.count("file blocks written")
            else:
                self.fail(b, f"a `{b.lang or 'plain'}` block that nothing runs: give it a language this "
                          "test runs, or a quoted from / run by / not run line before it")

    def check_marker(self, b):
        kind, value = b.marker
        if kind == "not run":
            if not value:
                self.fail(b, "`not run` needs a reason")
            self.count("blocks not run (with a reason)")
        elif kind == "run by":
            script = os.path.join(self.args.source, value)
            if not os.path.isfile(script):
                self.fail(b, f"run by {value}: no such file")
            elif os.path.basename(b.page) not in open(script, encoding="utf-8").read():
                self.fail(b, f"run by {value}: it does not name {b.page}")
            self.count("blocks run by other tests")
        else:
            stripped = [line.strip() for line in b.body]
            sources = value.split()
            found = False
            for source in sources:
                path = os.path.join(self.args.source, source)
                if not os.path.isfile(path):
                    self.fail(b, f"quoted from {source}: no such file")
                    continue
                if contains([line.strip() for line in open(path, encoding="utf-8").read().splitlines()], stripped):
                    found = True
            if not found:
                self.fail(b, f"not found in {' '.join(sources)}: {stripped[0] if stripped else '(empty)'}")
            self.count("blocks quoted from built examples")

    def check_output(self, b, previous, outputs):
        self.count("outputs compared")
        if previous is None:
            self.fail(b, "an output block with no cpp or python block before it")
            return
        if previous.lang == "python" and not self.args.python_path:
            return
        got = outputs.get(previous.where())
        if got is None:
            self.fail(b, f"the block at line {previous.line} did not run (for a cpp block: is doc_snippets "
                      "built from this version of the page?)")
        elif got.rstrip("\n").splitlines() != b.body:
            self.fail(b, f"the block at line {previous.line} printed\n    " + "\n    ".join(got.splitlines()))

    def check_console(self, b, work):
        for command, expected in console_steps(b.body):
            r = self.run(command, work)
            if r.returncode != 0:
                self.fail(b, f"`{command}` exited {r.returncode}: {r.stderr.strip()[-2000:]}")
            elif r.stdout.rstrip("\n").splitlines() != expected:
                self.fail(b, f"`{command}` printed\n    " + "\n    ".join(r.stdout.splitlines()))
        self.count("console blocks run")

    def check_query(self, b, work):
        self.count("json queries run")
        r = self.run("proxima query", work, stdin="\n".join(b.body) + "\n")
        answer = r.stdout.rstrip("\n").splitlines()
        if r.returncode != 0:
            self.fail(b, f"`proxima query` exited {r.returncode}: {r.stderr.strip()}")
        return answer


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "cpp":
        if len(sys.argv) < 4:
            raise SystemExit(__doc__)
        write_cpp(sys.argv[2], sys.argv[3:])
        return 0
    parser = argparse.ArgumentParser(usage=__doc__)
    parser.add_argument("mode", choices=["check"])
    parser.add_argument("--source", required=True)
    parser.add_argument("--build", required=True)
    parser.add_argument("--snippets", required=True)
    parser.add_argument("--cli-dir", required=True)
    parser.add_argument("--python-path")
    parser.add_argument("pages", nargs="+")
    args = parser.parse_args()
    checker = Checker(args)
    for path in args.pages:
        checker.check_page(path, os.path.relpath(os.path.abspath(path), os.path.abspath(args.source)))
    for what, n in sorted(checker.counts.items()):
        print(f"{n:4d} {what}")
    for failure in checker.failures:
        print("FAILED " + failure)
    print(f"{len(args.pages)} pages, {len(checker.failures)} failures")
    return 1 if checker.failures else 0


sys.exit(main())
