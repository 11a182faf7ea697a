"""`testbed family write` writes members that reload as the family drew them, and `testbed
summary --by` groups a sweep's rows as asked."""

from testbed.cli import main
from testbed.pipeline.scenario import load_scenario
from testbed.studies.study import load_study


def test_family_write_members_reload_equal(tmp_path, capsys):
    assert main(["family", "write", "families", "-o", str(tmp_path), "--family", "beams_soft"]) == 0
    written = sorted(tmp_path.glob("*.toml"))
    members = [m for m in load_study("families").scenarios if m.name.startswith("beams_soft__")]
    assert len(written) == len(members) > 0
    again = load_scenario(written[3])
    drawn = {m.name: m for m in members}[again.name]
    assert (again.rig_params, again.simulation, again.excitation) == \
        (drawn.rig_params, drawn.simulation, drawn.excitation)


def test_family_write_unknown_study_is_one_line(tmp_path, capsys):
    assert main(["family", "write", "no_such_study", "-o", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "no_such_study" in err
