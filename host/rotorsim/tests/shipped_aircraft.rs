//! The shipped aircraft files give the simulator the very numbers its presets were
//! compiled with before the files existed, bit for bit: the presets below are those
//! compiled parameter sets, kept as the reference. A campaign of a shipped vehicle is
//! byte-identical only if these hold.

use rotorsim::{Gearing, Helicopter, Rotor, Surface};

fn bo105_as_compiled() -> Helicopter {
    let deg = std::f64::consts::PI / 180.0;
    Helicopter {
        name: "Bo-105".into(),
        mass: 2200.0,
        ixx: 1433.0,
        iyy: 4973.0,
        izz: 4099.0,
        ixz: 660.0,
        air_density: 1.225,
        gravity: 9.80665,
        main_rotor: Rotor {
            radius: 4.91,
            omega: 44.4,
            blades: 4.0,
            chord: 0.27,
            twist: -0.14,
            lift_slope: 6.113,
            flap_inertia: 231.7,
            hub_stiffness: 113_330.0,
            profile_drag: [0.0074, 38.66],
            // CG 0.0163 R forward of the shaft, hub 1.48 m above the CG.
            hub: [-0.0163 * 4.91, 0.0, -1.48],
        },
        shaft_tilt: 0.0524,
        tail_rotor: Rotor {
            radius: 0.95,
            omega: 2220.0 * 2.0 * std::f64::consts::PI / 60.0,
            blades: 2.0,
            chord: 0.18,
            twist: 0.0,
            lift_slope: 5.7,
            flap_inertia: 1.0,
            hub_stiffness: 0.0,
            profile_drag: [0.008, 9.5],
            hub: [-6.0, 0.0, -1.72],
        },
        fuselage_drag_area: [1.4, 8.0, 10.0],
        fin: Surface {
            area: 0.805,
            incidence: 0.0812,
            lift_slope: 2.704,
            position: [-5.4, 0.0, -0.9],
            stall_angle: 0.35,
        },
        tailplane: Surface {
            area: 0.803,
            incidence: 0.0698,
            lift_slope: 3.262,
            position: [-4.56, 0.0, -0.2],
            stall_angle: 0.35,
        },
        gearing: [
            Gearing {
                centre: 0.0,
                gain: -8.0 * deg,
            },
            Gearing {
                centre: 0.0,
                gain: 10.0 * deg,
            },
            Gearing {
                centre: 8.5 * deg,
                gain: -16.5 * deg,
            },
            Gearing {
                centre: 11.0 * deg,
                gain: 9.0 * deg,
            },
        ],
    }
}

fn trex700l_as_compiled() -> Helicopter {
    let deg = std::f64::consts::PI / 180.0;
    Helicopter {
        name: "TREX 700L class (approximate)".into(),
        mass: 5.0,
        ixx: 0.12,
        iyy: 0.40,
        izz: 0.35,
        ixz: 0.0,
        air_density: 1.225,
        gravity: 9.80665,
        main_rotor: Rotor {
            radius: 0.78,
            omega: 1900.0 * 2.0 * std::f64::consts::PI / 60.0,
            blades: 2.0,
            chord: 0.062,
            twist: 0.0,
            lift_slope: 5.5,
            flap_inertia: 0.046,
            hub_stiffness: 350.0,
            profile_drag: [0.012, 0.0],
            hub: [0.0, 0.0, -0.25],
        },
        shaft_tilt: 0.0,
        tail_rotor: Rotor {
            radius: 0.135,
            omega: 1900.0 * 4.7 * 2.0 * std::f64::consts::PI / 60.0,
            blades: 2.0,
            chord: 0.032,
            twist: 0.0,
            lift_slope: 5.0,
            flap_inertia: 1.0,
            hub_stiffness: 0.0,
            profile_drag: [0.012, 0.0],
            hub: [-0.95, 0.0, -0.12],
        },
        fuselage_drag_area: [0.03, 0.10, 0.12],
        fin: Surface {
            area: 0.012,
            incidence: 0.0,
            lift_slope: 3.0,
            position: [-0.90, 0.0, -0.05],
            stall_angle: 0.35,
        },
        tailplane: Surface {
            area: 0.010,
            incidence: 0.0,
            lift_slope: 3.0,
            position: [-0.70, 0.0, 0.0],
            stall_angle: 0.35,
        },
        gearing: [
            Gearing {
                centre: 0.0,
                gain: -8.0 * deg,
            },
            Gearing {
                centre: 0.0,
                gain: 8.0 * deg,
            },
            Gearing {
                centre: 5.0 * deg,
                gain: -25.0 * deg,
            },
            Gearing {
                centre: 2.0 * deg,
                gain: 12.0 * deg,
            },
        ],
    }
}
#[test]
fn the_shipped_files_are_the_compiled_presets_bit_for_bit() {
    assert_eq!(Helicopter::bo105(), bo105_as_compiled());
    assert_eq!(Helicopter::trex700l(), trex700l_as_compiled());
}

#[test]
fn a_changed_file_value_reaches_the_simulator() {
    let text = aircraft::SHIPPED[1]
        .1
        .replace("mass = \"5.0 kg\"", "mass = \"5600 g\"");
    let file = aircraft::parse(&text, "variant.toml").unwrap();
    let heli = Helicopter::from_aircraft(&file);
    assert_eq!(heli.mass, 5.6);
    assert_eq!(Helicopter { mass: 5.0, ..heli }, trex700l_as_compiled());
}
