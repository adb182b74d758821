"""An IDF's text, read and checked before any parser sees it: the standard library only, so that
a command refuses a file it cannot read, or a truncated one, before it loads the model."""

from nodeforce.model.errors import InputError


def unterminated_object(text):
    """The first line of the object an IDF text leaves open (its last object without the ';' that
    ends it, as a truncated file does), None if every object is closed. Read before idfkit parses
    the file: its object pattern backtracks exponentially on an open tail (20, 25, 30 characters:
    0.03, 1.1, 40 s), where this reads the text once."""
    code = [line.split("!", 1)[0] for line in text.splitlines()]
    tail = "\n".join(code).rsplit(";", 1)[-1]
    if tail.strip() == "":
        return None
    return next(line.strip() for line in tail.splitlines() if line.strip())


def closed_text(path):
    """The text of the IDF at `path`; InputError naming the file for one that is missing,
    unreadable, or whose last object is left open."""
    try:
        text = open(path, encoding="utf-8", errors="replace").read()
    except FileNotFoundError:
        raise InputError(path, "file", "not found") from None
    except OSError as e:
        raise InputError(path, "file", f"cannot be read ({e.strerror})") from None
    open_object = unterminated_object(text)
    if open_object is not None:
        kind = open_object.split(",")[0].strip()
        raise InputError(path, kind or "(file)", f"the object {open_object[:40]!r} has no closing ';': the file is "
                                                 "truncated or its last object unterminated")
    return text
