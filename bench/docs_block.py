"""Writes a bench's block into docs/benchmarks.md between its markers, or appends it under a
section title when the markers are not there yet."""


def replace_block(path, begin, end, block, title):
    with open(path) as f:
        text = f.read()
    section = f"{begin}\n{block}\n{end}"
    if begin in text and end in text:
        text = text[:text.index(begin)] + section + text[text.index(end) + len(end):]
    else:
        text += f"\n## {title}\n\n{section}\n"
    with open(path, "w") as f:
        f.write(text)
