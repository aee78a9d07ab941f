"""The package's exceptions: SceneError (bad scene or override, the CLI's exit code 2) and
SolveError (a failed solve, exit code 3, carrying everything computed up to the failure)."""
import re

# The CLI's line format (docs/errors.md): FILE:LINE: field 'FIELD': MESSAGE, with LINE and
# the field part optional.
_LINE = re.compile(r"^(?P<file>.*?)(?::(?P<line>\d+))?(?:: field '(?P<field>[^']*)')?: (?P<message>.*)$", re.S)


def parse_error_line(text):
    """Splits one CLI error line into {file, line, field, message} (line 0 / field '' if absent)."""
    m = _LINE.match(text)
    if not m:
        return {"file": "", "line": 0, "field": "", "message": text}
    return {"file": m["file"], "line": int(m["line"] or 0), "field": m["field"] or "", "message": m["message"]}


class SceneError(ValueError):
    """A scene, model file or parameter override that cannot be used. `str(e)` is what the CLI
    prints (one line per problem); `file`, `line`, `field`, `message` are the first problem's,
    `errors` has every problem as a dict and `lines` the printed lines."""

    def __init__(self, lines):
        self.lines = list(lines)
        self.errors = [parse_error_line(s) for s in self.lines]
        first = self.errors[0] if self.errors else {"file": "", "line": 0, "field": "", "message": ""}
        self.file, self.line, self.field, self.message = first["file"], first["line"], first["field"], first["message"]
        super().__init__("\n".join(self.lines))

    def __reduce__(self):
        return (SceneError, (self.lines,))


class SolveError(RuntimeError):
    """A run that did not succeed (assembly, equilibrium or integration failed, or it was
    interrupted). `result` is the partial Result; `status` and `message` are its."""

    def __init__(self, result):
        self.result = result
        self.status = result.status
        self.message = result.message
        super().__init__(f"{result.status}: {result.message}")

    def __reduce__(self):
        return (SolveError, (self.result,))
