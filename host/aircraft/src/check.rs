//! From the file's written values to an [`Aircraft`]: each value read in its dimension,
//! then checked against the range a physical helicopter can have, then the checks that
//! relate values (inertia, tip speeds, tail smaller than main rotor). The ranges are wide
//! on purpose — from a 0.5 kg model to a heavy helicopter — and catch what no aircraft
//! can be (zero, negative, non-finite values, a value in the wrong scale), not what is
//! merely unusual. They are listed in `docs/formats.md`.

use crate::flight_controller;
use crate::quantity::{Dimension, Quantity};
use crate::reader::{show, Range, Reader, DEG};
use crate::schema;
use crate::{
    Aircraft, AircraftError, Airframe, Controls, Environment, Identification, MainRotor, Rotation,
    Servos, TailRotor, TrimBalance, ValidRanges,
};

/// Read and check a whole file.
pub(crate) fn aircraft(
    file: &schema::File,
    text: &str,
    source_name: &str,
) -> Result<Aircraft, AircraftError> {
    let r = Reader { text, source_name };
    let name = file.name.get_ref().trim();
    if name.is_empty()
        || !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
    {
        return Err(r.error(
            file.name.span().start,
            "name",
            "must be a non-empty word of letters, digits, `-` and `_` (it names the aircraft on the command line)",
        ));
    }
    use Dimension as D;
    use Range::{Between, NonNegative, Positive};

    let e = &file.environment;
    let environment = Environment {
        air_density: r.value(
            &e.air_density,
            "environment.air_density",
            D::Density,
            Between(0.3, 1.5),
        )?,
        gravity: r.value(
            &e.gravity,
            "environment.gravity",
            D::Acceleration,
            Between(9.7, 9.9),
        )?,
    };

    let a = &file.airframe;
    let airframe = Airframe {
        mass: r.value(&a.mass, "airframe.mass", D::Mass, Positive(50_000.0))?,
        ixx: r.value(&a.ixx, "airframe.ixx", D::Inertia, Positive(1e6))?,
        iyy: r.value(&a.iyy, "airframe.iyy", D::Inertia, Positive(1e6))?,
        izz: r.value(&a.izz, "airframe.izz", D::Inertia, Positive(1e6))?,
        ixz: r.value(&a.ixz, "airframe.ixz", D::Inertia, Between(-1e6, 1e6))?,
        drag_area: r.values(
            &a.drag_area,
            "airframe.drag_area",
            D::Area,
            NonNegative(100.0),
        )?,
    };
    check_inertia(&r, a, &airframe)?;

    let m = &file.main_rotor;
    let rotation = match m.rotation.get_ref().as_str() {
        "counterclockwise" | "ccw" => Rotation::Counterclockwise,
        "clockwise" | "cw" => {
            return Err(r.error(
                m.rotation.span().start,
                "main_rotor.rotation",
                "the simulator models rotors turning counterclockwise seen from above only",
            ))
        }
        other => {
            return Err(r.error(
                m.rotation.span().start,
                "main_rotor.rotation",
                format!("`{other}`: expected counterclockwise or clockwise"),
            ))
        }
    };
    let main_rotor = MainRotor {
        radius: r.value(&m.radius, "main_rotor.radius", D::Length, Positive(20.0))?,
        head_speed: r.value(
            &m.head_speed,
            "main_rotor.head_speed",
            D::AngularSpeed,
            Positive(500.0),
        )?,
        rotation,
        blades: r.blades(&m.blades, "main_rotor.blades")?,
        chord: r.value(&m.chord, "main_rotor.chord", D::Length, Positive(2.0))?,
        twist: r.value(
            &m.twist,
            "main_rotor.twist",
            D::Angle,
            Between(-30.0 * DEG, 30.0 * DEG),
        )?,
        lift_slope: r.lift_slope(&m.lift_slope, "main_rotor.lift_slope")?,
        flap_inertia: r.value(
            &m.flap_inertia,
            "main_rotor.flap_inertia",
            D::Inertia,
            Positive(1e5),
        )?,
        hub_stiffness: r.value(
            &m.hub_stiffness,
            "main_rotor.hub_stiffness",
            D::Stiffness,
            NonNegative(1e8),
        )?,
        profile_drag: r.profile_drag(&m.profile_drag, "main_rotor.profile_drag")?,
        hub: r.position(&m.hub, "main_rotor.hub")?,
        shaft_tilt: r.value(
            &m.shaft_tilt,
            "main_rotor.shaft_tilt",
            D::Angle,
            Between(-20.0 * DEG, 20.0 * DEG),
        )?,
    };
    check_rotor(
        &r,
        ("main_rotor.head_speed", m.head_speed.span().start),
        ("main_rotor.chord", m.chord.span().start),
        [
            &main_rotor.radius,
            &main_rotor.chord,
            &main_rotor.head_speed,
        ],
    )?;
    if main_rotor.blades < 2 {
        return Err(r.error(
            m.blades.span().start,
            "main_rotor.blades",
            "a main rotor has at least 2 blades",
        ));
    }

    let t = &file.tail_rotor;
    let tail_radius = r.value(&t.radius, "tail_rotor.radius", D::Length, Positive(5.0))?;
    if tail_radius.value >= main_rotor.radius.value {
        return Err(r.error(
            t.radius.span().start,
            "tail_rotor.radius",
            format!(
                "{} m is not smaller than the main rotor's {} m",
                show(tail_radius.value),
                show(main_rotor.radius.value)
            ),
        ));
    }
    let speed = match (&t.speed, &t.gear_ratio) {
        (Some(speed), None) => {
            r.value(speed, "tail_rotor.speed", D::AngularSpeed, Positive(2000.0))?
        }
        (None, Some(ratio)) => {
            let ratio = r.value(
                ratio,
                "tail_rotor.gear_ratio",
                D::Dimensionless,
                Between(1.0, 20.0),
            )?;
            Quantity {
                value: ratio.value * main_rotor.head_speed.value,
                sigma: ratio.sigma.map(|s| s * main_rotor.head_speed.value),
            }
        }
        (Some(speed), Some(_)) => {
            return Err(r.error(
                speed.span().start,
                "tail_rotor.speed",
                "give speed or gear_ratio, not both",
            ))
        }
        (None, None) => {
            return Err(r.error(
                t.radius.span().start,
                "tail_rotor.speed",
                "missing: give speed or gear_ratio",
            ))
        }
    };
    let tail_rotor = TailRotor {
        radius: tail_radius,
        speed,
        blades: r.blades(&t.blades, "tail_rotor.blades")?,
        chord: r.value(&t.chord, "tail_rotor.chord", D::Length, Positive(1.0))?,
        twist: r.value(
            &t.twist,
            "tail_rotor.twist",
            D::Angle,
            Between(-30.0 * DEG, 30.0 * DEG),
        )?,
        lift_slope: r.lift_slope(&t.lift_slope, "tail_rotor.lift_slope")?,
        profile_drag: r.profile_drag(&t.profile_drag, "tail_rotor.profile_drag")?,
        hub: r.position(&t.hub, "tail_rotor.hub")?,
    };
    let (speed_field, speed_at) = match (&t.speed, &t.gear_ratio) {
        (Some(speed), _) => ("tail_rotor.speed", speed.span().start),
        (_, Some(ratio)) => ("tail_rotor.gear_ratio", ratio.span().start),
        _ => ("tail_rotor.speed", t.radius.span().start),
    };
    check_rotor(
        &r,
        (speed_field, speed_at),
        ("tail_rotor.chord", t.chord.span().start),
        [&tail_rotor.radius, &tail_rotor.chord, &tail_rotor.speed],
    )?;
    if tail_rotor.hub[0].value >= 0.0 {
        return Err(r.error(
            t.hub.span().start,
            "tail_rotor.hub[0]",
            "the tail rotor must be behind the CG (x < 0)",
        ));
    }

    let c = &file.controls;
    let controls = Controls {
        lat: r.gearing(&c.lat, "controls.lat")?,
        lon: r.gearing(&c.lon, "controls.lon")?,
        ped: r.gearing(&c.ped, "controls.ped")?,
        col: r.gearing(&c.col, "controls.col")?,
    };

    let s = &file.servos;
    let servos = Servos {
        natural_frequency: r.value(
            &s.natural_frequency,
            "servos.natural_frequency",
            D::AngularSpeed,
            Positive(2000.0),
        )?,
        damping: r.value(
            &s.damping,
            "servos.damping",
            D::Dimensionless,
            Positive(3.0),
        )?,
        rate_limit: r.value(
            &s.rate_limit,
            "servos.rate_limit",
            D::PerTime,
            Positive(1000.0),
        )?,
        transport_delay: r.value(
            &s.transport_delay,
            "servos.transport_delay",
            D::Time,
            NonNegative(0.5),
        )?,
    };

    let swash = match &file.swash {
        Some(table) => crate::swash::read(&r, table)?,
        None => crate::Swash::default(),
    };
    let flight_controller = flight_controller::read(&r, &file.flight_controller)?;
    let identification = identification(&r, &file.identification)?;

    Ok(Aircraft {
        name: name.to_string(),
        title: file.title.as_deref().map_or(name, str::trim).to_string(),
        description: file.description.trim().to_string(),
        environment,
        airframe,
        main_rotor,
        tail_rotor,
        fin: r.surface(&file.fin, "fin")?,
        tailplane: r.surface(&file.tailplane, "tailplane")?,
        controls,
        servos,
        swash,
        flight_controller,
        identification,
    })
}

fn identification(r: &Reader, i: &schema::Identification) -> Result<Identification, AircraftError> {
    let bands = i.sweep_bands.get_ref();
    if bands.len() != 2 {
        return Err(r.error(
            i.sweep_bands.span().start,
            "identification.sweep_bands",
            format!("expected 2 bands, found {}", bands.len()),
        ));
    }
    let mut sweep_bands = [[0.0; 2]; 2];
    for (k, (slot, band)) in sweep_bands.iter_mut().zip(bands).enumerate() {
        let field = format!("identification.sweep_bands[{k}]");
        let [low, high] =
            r.values::<2>(band, &field, Dimension::AngularSpeed, Range::Positive(1e4))?;
        if high.value <= low.value {
            return Err(r.error(band.span().start, &field, "ω_max must exceed ω_min"));
        }
        *slot = [low.value, high.value];
    }
    let word = |written: &toml::Spanned<String>, field: &str, choices: &[&str]| {
        let value = written.get_ref().as_str();
        choices.iter().position(|c| *c == value).ok_or_else(|| {
            r.error(
                written.span().start,
                field,
                format!("`{value}`: expected {}", choices.join(" or ")),
            )
        })
    };
    let trim_balance = match word(
        &i.trim_balance,
        "identification.trim_balance",
        &["hold", "joint"],
    )? {
        0 => TrimBalance::Hold,
        _ => TrimBalance::Joint,
    };
    let valid_ranges = match word(
        &i.valid_ranges,
        "identification.valid_ranges",
        &["estimate", "sweep-reference"],
    )? {
        0 => ValidRanges::Estimate,
        _ => ValidRanges::SweepReference,
    };
    let structure = i.structure.get_ref().trim();
    if structure.is_empty() {
        return Err(r.error(
            i.structure.span().start,
            "identification.structure",
            "must name a structure",
        ));
    }
    Ok(Identification {
        sweep_bands,
        structure: structure.to_string(),
        trim_balance,
        valid_ranges,
    })
}

/// A rigid body's inertias obey the triangle inequalities (I_xx + I_yy ≥ I_zz and its
/// permutations), and its inertia tensor is positive definite: I_xz² < I_xx·I_zz.
fn check_inertia(r: &Reader, a: &schema::Airframe, f: &Airframe) -> Result<(), AircraftError> {
    let (x, y, z) = (f.ixx.value, f.iyy.value, f.izz.value);
    for (sum, other, field, at) in [
        (x + y, z, "airframe.izz", &a.izz),
        (y + z, x, "airframe.ixx", &a.ixx),
        (z + x, y, "airframe.iyy", &a.iyy),
    ] {
        if other > sum {
            return Err(r.error(
                at.span().start,
                field,
                format!("{} kg*m^2 exceeds the sum of the other two inertias ({} kg*m^2): no rigid body has these", show(other), show(sum)),
            ));
        }
    }
    if f.ixz.value * f.ixz.value >= x * z {
        return Err(r.error(
            a.ixz.span().start,
            "airframe.ixz",
            "I_xz² must be smaller than I_xx·I_zz (the inertia tensor is positive definite)",
        ));
    }
    Ok(())
}

/// Tip speed below Mach 0.9 at sea level; chord at most a quarter of the radius. The
/// places are (field, byte offset) of the speed and the chord.
fn check_rotor(
    r: &Reader,
    speed_at: (&str, usize),
    chord_at: (&str, usize),
    [radius, chord, speed]: [&Quantity; 3],
) -> Result<(), AircraftError> {
    let tip = speed.value * radius.value;
    if tip > 310.0 {
        return Err(r.error(
            speed_at.1,
            speed_at.0,
            format!("tip speed {tip:.0} m/s is above Mach 0.9: is the speed in the right unit (rpm or rad/s)?"),
        ));
    }
    if chord.value > radius.value / 4.0 {
        return Err(r.error(
            chord_at.1,
            chord_at.0,
            format!(
                "{} m is more than a quarter of the radius {} m",
                show(chord.value),
                show(radius.value)
            ),
        ));
    }
    Ok(())
}
