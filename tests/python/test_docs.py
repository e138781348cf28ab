"""docs/python.md's examples run as written: every ```python block, in order, in one namespace,
from the project's root. The blocks that read real data (they name STRATA_DATA_DIR) run in a
test of their own, so that the others are tested where the data is absent too."""
import os
import re

from conftest import DATA_DIR, SOURCE_DIR, skip_without_data


def doc_blocks() -> list:
    text = (SOURCE_DIR / "docs" / "python.md").read_text()
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def needs_data(block: str) -> bool:
    return "STRATA_DATA_DIR" in block


def run_blocks(blocks, monkeypatch) -> dict:
    monkeypatch.chdir(SOURCE_DIR)
    monkeypatch.setenv("STRATA_DATA_DIR", str(DATA_DIR))
    namespace = {}
    for block in blocks:
        exec(compile(block, "docs/python.md", "exec"), namespace)
    return namespace


def test_the_examples_without_real_data_run(monkeypatch):
    blocks = doc_blocks()
    assert len(blocks) >= 4 and any(needs_data(b) for b in blocks)
    namespace = run_blocks([b for b in blocks if not needs_data(b)], monkeypatch)
    assert len(namespace["walls"]["walls"]) == 10  # the street's ten walls (ground truth)
    kinds = {(o["kind"], o["class"]) for o in namespace["changes"]["objects"]}
    assert {("added", "vehicle"), ("removed", "vehicle"), ("added", "other")} <= kinds
    if os.environ.get("STRATA_KEEP_DOC_PICTURES"):  # how docs/images/python_slant.png is made
        (SOURCE_DIR / "docs" / "images" / "python_slant.png").write_bytes(
            (namespace["work"] / "slant.png").read_bytes())


def test_the_examples_with_real_data_run(monkeypatch):
    skip_without_data(DATA_DIR / "kitti00" / "velodyne")
    blocks = doc_blocks()
    last = max(i for i, b in enumerate(blocks) if needs_data(b))
    namespace = run_blocks(blocks[:last + 1], monkeypatch)
    assert (namespace["work"] / "kitti00.png").stat().st_size > 1000
