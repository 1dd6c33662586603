# SPDX-License-Identifier: Apache-2.0
"""Schema validations remembered by content (ima.schema_memo): valid documents only, by the
document's and the schema's content."""

from __future__ import annotations

import shutil
from pathlib import Path

import jsonschema
import pytest

from ima import paths, schema_memo
from ima.deploy import load
from ima.deploy.model import SystemModelError
from imaworld import pilot

SYSTEM = paths.repo_root() / "config" / "systems" / "rpas_simplex.yaml"


@pytest.fixture
def build(tmp_path, monkeypatch):
    monkeypatch.setenv("IMA_BUILD_DIR", str(tmp_path / "build"))
    return tmp_path / "build"


def _no_validator(monkeypatch):
    """From here on, a validation that runs fails the test."""
    def refuse(*_a, **_k):
        raise AssertionError("validated again")
    monkeypatch.setattr(jsonschema, "Draft202012Validator", refuse)


def test_a_valid_document_is_remembered_and_not_validated_again(build, monkeypatch):
    assert not schema_memo.known_valid(b"schema", {"a": 1})
    load.load_system(SYSTEM)
    assert len(list((build / "validated").iterdir())) == 1
    _no_validator(monkeypatch)
    assert load.load_system(SYSTEM).name == load.load_system(SYSTEM).name


def test_another_document_or_schema_is_not_known(build):
    schema_memo.remember_valid(b"schema", {"a": 1, "b": [1.5, None]})
    assert schema_memo.known_valid(b"schema", {"a": 1, "b": [1.5, None]})
    assert not schema_memo.known_valid(b"schema", {"a": 1, "b": [1.5, 0]})
    assert not schema_memo.known_valid(b"schema", {"a": 1.0, "b": [1.5, None]})  # a float
    assert not schema_memo.known_valid(b"schema 2", {"a": 1, "b": [1.5, None]})


def test_an_invalid_document_is_refused_every_time_and_never_remembered(build, tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("start: {altitude_ft: 3000, airspeed_kt: 100, heading_deg: 90}\n"
                   "events: [{t: 0, mode: HOVER}]\n")
    for _ in range(2):
        with pytest.raises(pilot.PilotScriptError, match=r"events\[0\]\.mode"):
            pilot.load(bad)
    assert not (build / "validated").exists()


def test_a_system_model_changed_after_it_was_found_valid_is_validated_again(build, tmp_path):
    model = tmp_path / "systems" / "system.yaml"
    shutil.copytree(SYSTEM.parent.parent, tmp_path, dirs_exist_ok=True)  # its include too
    shutil.copy(SYSTEM, model)
    load.load_system(model)
    model.write_text(model.read_text() + "\nnot_a_key: 1\n")
    with pytest.raises(SystemModelError, match="not_a_key"):
        load.load_system(model)


def test_without_a_usable_build_tree_documents_are_validated(tmp_path, monkeypatch):
    blocked = tmp_path / "file"
    blocked.write_text("")
    monkeypatch.setenv("IMA_BUILD_DIR", str(blocked))  # validated/ cannot be made in a file
    script = pilot.load(paths.repo_root() / "sim" / "pilots" / "default.yaml")
    assert script.start["altitude_ft"] > 0
    assert not schema_memo.known_valid(pilot._schema_text(), script.start)
    calls = []
    real = jsonschema.Draft202012Validator
    monkeypatch.setattr(jsonschema, "Draft202012Validator",
                        lambda *a, **k: calls.append(1) or real(*a, **k))
    pilot.load(paths.repo_root() / "sim" / "pilots" / "default.yaml")
    assert calls  # validated again: nothing was remembered

    def unsearchable(_path):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(Path, "is_file", unsearchable)  # validated/ may not be looked into
    calls.clear()
    assert not schema_memo.known_valid(pilot._schema_text(), script.start)
    pilot.load(paths.repo_root() / "sim" / "pilots" / "default.yaml")
    assert calls
