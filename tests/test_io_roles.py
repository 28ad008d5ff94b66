"""Channel roles: detection by quantity, then by name; overrides; ambiguity errors."""

from __future__ import annotations

import numpy as np
import pytest

from pidcore.errors import ChannelError
from pidcore.io import RoleAssignment, assign_roles, name_suggests
from pidcore.records import Channel, Measurement


def _ch(name: str, quantity: str, unit: str = "") -> Channel:
    return Channel(name, quantity, np.zeros(8), 100.0, unit)


def _m(*channels: Channel) -> Measurement:
    return Measurement("run.uff", tuple(channels))


def test_detect_by_quantity_whatever_the_names():
    m = _m(_ch("ch1", "acceleration", "g"), _ch("ch2", "force", "N"),
           _ch("ch3", "velocity", "mm/s"), _ch("mic", "pressure", "Pa"))
    roles = assign_roles(m, mass_cancellation=True)
    assert isinstance(roles, RoleAssignment)
    assert (roles.force.name, roles.velocity.name, roles.acceleration.name) == \
        ("ch2", "ch3", "ch1")
    # without mass cancellation the acceleration is not needed beside a velocity: ignored
    roles = assign_roles(m)
    assert roles.acceleration is None and roles.ignored == ("ch1", "mic")


def test_extra_channels_do_not_block_force_velocity_pair():
    """Two reference accelerometers, a microphone: none is needed, none blocks, all named."""
    m = _m(_ch("Force", "force", "N"), _ch("LDV", "velocity", "m/s"),
           _ch("Ref acc", "acceleration", "g"), _ch("Acc 2", "acceleration", "g"),
           _ch("Mic", "pressure", "Pa"))
    roles = assign_roles(m)
    assert roles.velocity.name == "LDV" and roles.acceleration is None
    assert roles.ignored == ("Ref acc", "Acc 2", "Mic")


def test_mass_cancellation_needs_the_drive_point_acceleration():
    two = _m(_ch("Force", "force", "N"), _ch("LDV", "velocity", "m/s"),
             _ch("Ref acc", "acceleration", "g"), _ch("Acc 2", "acceleration", "g"))
    with pytest.raises(ChannelError, match=r"2 acceleration channels.*drive point.*"
                                           r"acceleration=NAME"):
        assign_roles(two, mass_cancellation=True)
    assert assign_roles(two, mass_cancellation=True, acceleration="Acc 2").acceleration.name \
        == "Acc 2"
    ref_only = _m(_ch("Force", "force", "N"), _ch("LDV", "velocity", "m/s"),
                  _ch("Shaker table", "acceleration", "g"))
    with pytest.raises(ChannelError, match=r"'Shaker table' is named like a reference"):
        assign_roles(ref_only, mass_cancellation=True)
    # no acceleration channel at all: the velocity gives the acceleration (j n w V_n)
    none = _m(_ch("Force", "force", "N"), _ch("LDV", "velocity", "m/s"))
    assert assign_roles(none, mass_cancellation=True).acceleration is None


def test_two_force_channels_resolved_by_name():
    m = _m(_ch("Reaction", "force", "N"), _ch("Drive point force", "force", "N"),
           _ch("LDV", "velocity", "m/s"))
    roles = assign_roles(m)
    assert roles.force.name == "Drive point force"
    assert roles.acceleration is None


def test_two_force_channels_unnamed_is_ambiguous():
    m = _m(_ch("F1", "force", "N"), _ch("F2", "force", "N"), _ch("a", "acceleration", "g"))
    with pytest.raises(ChannelError) as info:
        assign_roles(m)
    message = str(info.value)
    assert "'F1'" in message and "'F2'" in message and "force=NAME" in message
    assert assign_roles(m, force="F2").force.name == "F2"


def test_unknown_quantity_channels_detected_by_name():
    m = _m(_ch("Kraft", "unknown"), _ch("Vibrometer 1", "unknown", "V"), _ch("x", "unknown"))
    roles = assign_roles(m)
    assert roles.force.name == "Kraft" and roles.velocity.name == "Vibrometer 1"
    assert roles.acceleration is None


def test_override_unknown_name_lists_channels():
    m = _m(_ch("F", "force", "N"), _ch("a", "acceleration", "g"))
    with pytest.raises(ChannelError, match=r"no channel named 'Force'.*'F', 'a'"):
        assign_roles(m, force="Force")


def test_override_refusal_says_the_expected_role_with_its_article():
    # the acceleration role's refusal read "expected a acceleration channel"
    m = _m(_ch("F", "force", "N"), _ch("acc", "acceleration", "g"))
    with pytest.raises(ChannelError) as refused:
        assign_roles(m, acceleration="F")
    assert "acceleration='F' is a force channel (N); expected an acceleration channel or " \
        "one without a unit" in str(refused.value)
    with pytest.raises(ChannelError, match=r"; expected a force channel or one without"):
        assign_roles(m, force="acc")


def test_override_of_other_quantity_refused_unknown_accepted():
    m = _m(_ch("F", "force", "N"), _ch("acc", "acceleration", "g"), _ch("raw", "unknown", "V^2"))
    with pytest.raises(ChannelError, match=r"force='acc' is an acceleration channel"):
        assign_roles(m, force="acc")
    # with the role's unit given (--force-unit) the file's unit is taken as wrong
    wrong = _m(_ch("Force", "velocity", "m/s"), _ch("LDV", "velocity", "m/s"))
    roles = assign_roles(wrong, force="Force", retyped={"force"})
    assert roles.force.name == "Force" and roles.velocity.name == "LDV"
    roles = assign_roles(m, force="raw")  # accepted here; the analysis asks for its unit
    assert roles.force.name == "raw" and roles.acceleration.name == "acc"  # no velocity


def test_same_channel_for_two_roles_refused():
    m = _m(_ch("raw", "unknown"), _ch("F", "force", "N"))
    with pytest.raises(ChannelError, match="several roles"):
        assign_roles(m, force="raw", velocity="raw")


def test_missing_force_and_missing_motion():
    with pytest.raises(ChannelError, match=r"no force channel.*force=NAME"):
        assign_roles(_m(_ch("v", "velocity", "m/s")))
    with pytest.raises(ChannelError, match=r"no velocity or acceleration channel"):
        assign_roles(_m(_ch("F", "force", "N"), _ch("mic", "pressure", "Pa")))


@pytest.mark.parametrize(("name", "role", "expected"), [
    ("Drive point force", "force", True), ("F", "force", True), ("Kraft_1", "force", True),
    ("LDV", "velocity", True), ("vel_z", "velocity", True), ("Acc 3", "acceleration", True),
    ("Accelerometer", "acceleration", True), ("a", "acceleration", True),
    ("1+Z", "force", False), ("Mic 01", "velocity", False), ("Field Voltage", "velocity", False),
])
def test_name_suggests(name, role, expected):
    assert name_suggests(name, role) is expected


def test_missing_force_reported_before_motion_ambiguity():
    m = _m(_ch("1+Z", "acceleration", "m/s2"), _ch("2+Z", "acceleration", "m/s2"))
    with pytest.raises(ChannelError, match="no force channel"):
        assign_roles(m)


def test_a_refusal_naming_thousands_of_channels_lists_a_few_and_counts_the_rest():
    """A MAT matrix read the wrong way round was 10240 channels, and the "one-line" refusal
    listing them was 173 kB: the first 12 are named and the rest counted, so the line stays
    under 12 names of at most 80 characters (about 1 kB with the words around them)."""
    many = _m(*(_ch(f"Signal 1.{i + 1}", "pressure", "Pa") for i in range(10240)))
    with pytest.raises(ChannelError) as err:
        assign_roles(many)
    message = str(err.value)
    assert "'Signal 1.12' and 10228 more" in message and "'Signal 1.13'" not in message
    assert len(message) < 1500
    few = _m(_ch("Mic", "pressure", "Pa"), _ch("Temp", "temperature", "K"))
    with pytest.raises(ChannelError, match=r"among 'Mic', 'Temp'[;( ]"):
        assign_roles(few)  # a short list stays whole
