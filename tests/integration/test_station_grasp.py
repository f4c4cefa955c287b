"""A scripted grasp in the full station: the WSG closes on an object's body and the arm lifts it."""

import pytest

from tg_drake.objects import get_object
from tg_drake.scenario import ObjectPlacement, Scenario
from tg_drake.simulation.scripted import grasp_and_lift
from tg_drake.station import make_station


@pytest.mark.parametrize("object_id, containment", [("can_02", "full"), ("cup_01", "empty")])
def test_scripted_grasp_keeps_the_object_in_the_hand(object_id, containment):
    scenario = Scenario(cameras={})  # no rendering needed here
    # The cup's handle points along +x of its frame; yaw 90° turns it away from the fingers.
    scenario.objects = [ObjectPlacement(id=object_id, pose="upright", xy=[0.0, 0.0], yaw=90,
                                        containment=containment)]
    height = get_object(object_id).extents[2]
    result = grasp_and_lift(scenario, object_name=object_id, p_W_grasp=[0.75, 0.0, 0.5 * height],
                            lift=0.10, render=False)
    assert result.gripper_rise > 0.07  # the arm did lift (PD tracking under load lags ~1–2 cm)
    # The object rose with the gripper: within 1 cm (pad compliance and slip while lifting).
    assert result.object_rise == pytest.approx(result.gripper_rise, abs=0.01)
    # Fingers closed on the object, not on air: the opening is about the object's diameter
    # (within 1 cm: pads' compliance and a cup's taper).
    diameter = get_object(object_id).dimensions["diameter"]
    assert result.finger_opening == pytest.approx(diameter, abs=0.01)
    assert result.hydroelastic_surfaces >= 2  # one per pad: contact is hydroelastic


def test_full_container_is_heavier():
    full = Scenario(cameras={}, objects=[ObjectPlacement(id="cup_01", containment="full")])
    empty = Scenario(cameras={}, objects=[ObjectPlacement(id="cup_01", containment="empty")])
    masses = []
    for scenario in (full, empty):
        diagram, station = make_station(scenario)
        context = station.plant.CreateDefaultContext()
        masses.append(station.plant.CalcTotalMass(context, [station.objects["cup_01"]]))
    water = 1000.0 * get_object("cup_01").cavity_volume
    assert masses[0] - masses[1] == pytest.approx(water, rel=1e-9)
    # library.yaml rounds the mass to 5 significant digits; the SDF carries the full value.
    assert masses[1] == pytest.approx(get_object("cup_01").mass, rel=1e-4)
