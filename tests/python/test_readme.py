"""The README's Python example, run verbatim from a folder holding a copy of testdata/."""
import os
import re
import shutil

README = os.path.join(os.environ["POLYDG_TESTDATA"], os.pardir, "README.md")


def readme_example():
    text = open(README, encoding="utf-8").read()
    section = text[text.index("\n## Python\n"):]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_the_readme_example_runs(tmp_path, monkeypatch, capsys):
    shutil.copytree(os.environ["POLYDG_TESTDATA"], tmp_path / "testdata")
    monkeypatch.chdir(tmp_path)
    exec(compile(readme_example(), "README.md", "exec"), {})
    printed = capsys.readouterr().out
    assert "elements, volume" in printed and "faces integrated" in printed
    assert (tmp_path / "torus_cut.vtu").exists()
    assert (tmp_path / "runs" / "torus" / "report.json").exists()
    assert "'ok'" in printed and "'failed'" not in printed
