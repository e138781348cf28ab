"""docs/python.md's examples run as written: every ```python block, in order, in one namespace,
from the project's root."""
import os
import re

import pytest

from conftest import DATA_DIR, SOURCE_DIR


def test_the_examples_of_docs_python_md_run(monkeypatch):
    if not (DATA_DIR / "kitti00" / "velodyne").is_dir():
        pytest.skip(f"real data absent: {DATA_DIR / 'kitti00'} (the first example reads it)")
    text = (SOURCE_DIR / "docs" / "python.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert len(blocks) >= 2
    monkeypatch.chdir(SOURCE_DIR)
    monkeypatch.setenv("STRATA_DATA_DIR", str(DATA_DIR))
    namespace = {}
    for block in blocks:
        exec(compile(block, "docs/python.md", "exec"), namespace)
    assert (namespace["work"] / "kitti00.png").stat().st_size > 1000
    assert len(namespace["walls"]["walls"]) == 10  # the street's ten walls (ground truth)
    kinds = {(o["kind"], o["class"]) for o in namespace["changes"]["objects"]}
    assert {("added", "vehicle"), ("removed", "vehicle"), ("added", "other")} <= kinds
    if os.environ.get("STRATA_KEEP_DOC_PICTURES"):  # how docs/images/python_slant.png is made
        (SOURCE_DIR / "docs" / "images" / "python_slant.png").write_bytes(
            (namespace["work"] / "slant.png").read_bytes())
