from hrc.organisations.templatetags.admin_records import record_detail


def test_a_record_detail_reads_as_a_line() -> None:
    detail = {"role": "operator", "teams": ["Crew", "Night"], "invited": False, "members": []}
    assert record_detail(detail) == "role: operator; teams: Crew, Night; invited: no; members: –"
