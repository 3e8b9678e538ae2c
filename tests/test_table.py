"""The report table writer: one set of headers and rows, Markdown and CSV that agree."""

import csv
import io

import pytest

from simoun_agent.table import csv_text, markdown_table, write_csv


def test_markdown_aligns_the_columns_the_align_letters_name():
    text = markdown_table(["a", "b", "c"], [[1, "x", 2.5]], align="lr")
    assert text == "| a | b | c |\n|---|---:|---|\n| 1 | x | 2.5 |"


def test_an_empty_cell_keeps_its_column():
    assert markdown_table(["a", "b"], [["x", ""]]).splitlines()[-1] == "| x |  |"


def test_mapping_rows_take_the_headers_order_and_leave_missing_cells_empty():
    rows = [{"b": 2, "a": 1}, {"a": 3}]
    assert markdown_table(["a", "b"], rows).splitlines()[2:] == ["| 1 | 2 |", "| 3 |  |"]
    assert list(csv.reader(io.StringIO(csv_text(["a", "b"], rows)))) == [
        ["a", "b"],
        ["1", "2"],
        ["3", ""],
    ]


def test_a_row_of_the_wrong_length_and_a_bad_align_are_refused():
    with pytest.raises(ValueError, match="2 cells for 3 columns"):
        markdown_table(["a", "b", "c"], [[1, 2]])
    with pytest.raises(ValueError, match="align"):
        markdown_table(["a"], [], align="c")


def test_csv_quotes_what_needs_it_and_write_csv_keeps_the_bytes(tmp_path):
    text = csv_text(["name", "note"], [["a,b", 'say "hi"']])
    assert text == 'name,note\r\n"a,b","say ""hi"""\r\n'
    write_csv(tmp_path / "t.csv", ["name", "note"], [["a,b", 'say "hi"']])
    assert (tmp_path / "t.csv").read_bytes() == text.encode()
