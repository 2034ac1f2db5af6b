"""The generated sections of the docs: the text between `<!-- NAME:begin -->` and
`<!-- NAME:end -->` is written from data, never by hand (ctest label docs checks it). The one
writer of those sections for every command that makes one."""
import re

BEGIN = re.compile(r"<!-- (\S+):begin -->")


def section(name):
    return re.compile(re.escape(f"<!-- {name}:begin -->") + ".*?" + re.escape(f"<!-- {name}:end -->"), re.S)


def names_in(text):
    """The sections a text has, in its order."""
    return BEGIN.findall(text)


def replace_between(text, name, body):
    """text with body between the markers of the section name (body ends in a newline), or
    None when the text has no such section."""
    pattern = section(name)
    if not pattern.search(text):
        return None
    return pattern.sub(lambda _: f"<!-- {name}:begin -->\n{body}<!-- {name}:end -->", text)


def update_file(path, sections, stale=None):
    """Writes the sections (name: body) that path has into it; with a list `stale`, writes
    nothing and appends to it the sections whose committed text differs. Returns the names of
    the sections found."""
    if not path.exists():
        print(f"note: {path} is missing, skipped")
        return []
    original = text = path.read_text()
    done = []
    for name, body in sections.items():
        new = replace_between(text, name, body)
        if new is None:
            continue
        done.append(name)
        if stale is not None and new != text:
            stale.append(f"{path}: {name}")
        text = new
    if stale is None and text != original:
        path.write_text(text)
    if stale is None and done:
        print(f"updated {path}: {', '.join(done)}")
    return done
