//! The typed view read back into table values ([`values_of`]): the inverse of
//! [`Params::from_values`](super::Params::from_values) on every field a parameter sets.

use super::*;

/// The table values of `params` (the inverse of [`Params::from_values`] on every
/// field a parameter sets).
pub fn values_of(params: &Params) -> [f32; COUNT] {
    let mut values = [0.0; COUNT];
    let mut put = |id: ParamId, value: f32| {
        if let Some(slot) = values.get_mut(id.index()) {
            *slot = value;
        }
    };
    let stack = &params.stack;
    let mixer = &stack.app.flight.mixer;
    put(ParamId::SwashType, f32::from(mixer.geometry.kind().code()));
    put(ParamId::SwashPhase, mixer.geometry.phase_deg());
    put(ParamId::SwashLead, f32::from(mixer.geometry.lead()));
    let [first, second, third] = SWASH_SERVO_IDS;
    let servo_ids = [first, second, third, TAIL_SERVO_IDS];
    let [swash1, swash2, swash3] = mixer.swash;
    let servos = [swash1, swash2, swash3, mixer.tail];
    for (ids, servo) in servo_ids.into_iter().zip(servos) {
        for (id, value) in ids.into_iter().zip(servo_values(&servo)) {
            put(id, value);
        }
    }
    put(ParamId::ServoRate, f32::from(params.swash_frame_hz));
    put(ParamId::TailRate, f32::from(params.tail_frame_hz));
    put(
        ParamId::CollMin,
        mixer.collective_offset - mixer.collective_scale,
    );
    put(
        ParamId::CollMax,
        mixer.collective_offset + mixer.collective_scale,
    );
    put(ParamId::CycScale, mixer.cyclic_scale);
    put(ParamId::PedScale, mixer.pedal_scale);
    put(ParamId::CycRing, mixer.cyclic_ring);

    let map = &stack.channel_map;
    let sources = [
        (ParamId::RcLat, map.lateral),
        (ParamId::RcLon, map.longitudinal),
        (ParamId::RcThr, map.throttle),
        (ParamId::RcPed, map.pedal),
        (ParamId::RcArm, map.arm),
        (ParamId::RcCol, map.collective),
        (ParamId::RcTest, map.test),
        (ParamId::RcMode, map.mode),
    ];
    let mut reversed = 0u8;
    for (bit, (id, source)) in sources.into_iter().enumerate() {
        put(id, f32::from(source.channel));
        reversed |= u8::from(source.reversed) << bit;
    }
    put(ParamId::RcRev, f32::from(reversed));
    put(ParamId::RcMin, f32::from(map.range.min));
    put(ParamId::RcMid, f32::from(map.range.centre));
    put(ParamId::RcMax, f32::from(map.range.max));
    put(ParamId::RcTimeout, (stack.rc_timeout_us / 1000) as f32);

    put(ParamId::ImuRot, f32::from(params.imu_rotation.code()));
    let notch_hz = |i: usize| {
        stack
            .filters
            .notches
            .get(i)
            .copied()
            .flatten()
            .map_or(0.0, |n| n.centre_hz)
    };
    put(ParamId::HeadRpm, notch_hz(0) * 60.0);
    put(ParamId::TailRpm, notch_hz(2) * 60.0);

    let flight = &stack.app.flight;
    let gains = [
        (
            flight.gains.lat,
            [
                ParamId::HoldLatP,
                ParamId::HoldLatI,
                ParamId::HoldLatD,
                ParamId::HoldLatLim,
            ],
        ),
        (
            flight.gains.lon,
            [
                ParamId::HoldLonP,
                ParamId::HoldLonI,
                ParamId::HoldLonD,
                ParamId::HoldLonLim,
            ],
        ),
        (
            flight.gains.ped,
            [
                ParamId::HoldPedP,
                ParamId::HoldPedI,
                ParamId::HoldPedD,
                ParamId::HoldPedLim,
            ],
        ),
    ];
    for ((axis, [p, i, d, limit]), [ilim, bump, fade, rev]) in gains.into_iter().zip(HOLD_MORE_IDS)
    {
        put(p, axis.kp);
        put(i, axis.ki);
        put(d, axis.kd);
        put(limit, axis.output_limit);
        put(ilim, axis.integrator_limit);
        put(bump, axis.bumpless_time_s);
        put(fade, axis.release_time_s);
        put(rev, if axis.reversed { 1.0 } else { 0.0 });
    }
    put(
        ParamId::HoldRef,
        match flight.hold_reference {
            HoldReference::Level => 0.0,
            HoldReference::Trim => 1.0,
        },
    );
    for (id, scale) in EXC_SCALE_IDS
        .into_iter()
        .zip(flight.excitation_scale.per_axis)
    {
        put(id, scale);
    }
    for (id, rate) in SLEW_IDS.into_iter().zip(flight.slew.per_s) {
        put(id, if rate.is_finite() { rate } else { 0.0 });
    }
    for (id, rate) in HOLD_SLEW_IDS.into_iter().zip(flight.hold_slew.per_s) {
        put(id, if rate.is_finite() { rate } else { 0.0 });
    }
    let test = &flight.test;
    put(ParamId::HoldEngage, test.hold_engage_rad / DEG);
    put(ParamId::HoldRelease, test.hold_release_rad / DEG);
    let safety = &flight.safety;
    put(ParamId::AbortAtt, safety.attitude_limit_rad / DEG);
    let [roll, pitch, yaw] = safety.rate_limit_rad_s;
    put(ParamId::AbortRateRoll, roll / DEG);
    put(ParamId::AbortRatePitch, pitch / DEG);
    put(ParamId::AbortRateYaw, yaw / DEG);
    put(ParamId::AbortStick, safety.pilot_override);

    let position = |axis: Axis| Axis::ALL.iter().position(|a| *a == axis).unwrap_or(0);
    put(ParamId::TestAxis, position(test.primary) as f32);
    let input = INPUTS.iter().position(|i| *i == test.input).unwrap_or(0);
    put(ParamId::TestInput, input as f32);
    let mode = MODES.iter().position(|m| *m == test.mode).unwrap_or(0);
    put(ParamId::TestMode, mode as f32);
    put(ParamId::SweepRecord, test.sweep.t_rec_s);
    put(ParamId::SweepAmp, test.sweep.amplitude);
    put(ParamId::SweepOmegaMin, test.sweep.omega_min);
    put(ParamId::SweepOmegaMax, test.sweep.omega_max);
    put(ParamId::SweepFade, test.sweep.fade_s);
    put(ParamId::SweepHold, f32::from(test.sweep.start_hold_cycles));
    put(ParamId::PulseAmp, test.pulse.amplitude);
    put(ParamId::PulseWidth, test.pulse.width_s);
    put(ParamId::NoiseRms, test.noise_rms);
    put(ParamId::NoiseCutoff, test.noise_cutoff_rad_s);
    put(ParamId::TestSeed, test.seed as f32);
    put(
        ParamId::TestFreeze,
        if test.freeze_in_band { 1.0 } else { 0.0 },
    );
    put(ParamId::Frame, frame_code(flight.vehicle));
    put(
        ParamId::TestColSrc,
        match flight.collective {
            CollectiveSource::Trim => 0.0,
            CollectiveSource::Pilot => 1.0,
        },
    );
    put(ParamId::AirColMin, stack.app.airborne.col_min);
    put(ParamId::AirTime, stack.app.airborne.time_s);
    put(ParamId::TestSelCh, f32::from(map.selector.channel));
    let list = &stack.app.tests;
    put(ParamId::TestSelN, f32::from(list.slices));
    for (k, entry) in list.entries.iter().enumerate().take(TEST_LIST_LEN) {
        for (f, value) in entry_values(entry).into_iter().enumerate() {
            put(entry_param(k, f), value);
        }
    }
    let pilot = &stack.app.pilot;
    for (axis, [kp, ki]) in [pilot.roll, pilot.pitch, pilot.yaw]
        .into_iter()
        .zip(PILOT_RATE_IDS)
    {
        put(kp, axis.kp);
        put(ki, axis.ki);
    }
    put(ParamId::PilotLevelGain, pilot.level_gain);
    put(ParamId::PilotHeadingGain, pilot.heading_gain);
    values
}

/// (direction, centre, min, max, throw) of a servo.
fn servo_values(servo: &ServoConfig) -> [f32; 5] {
    [
        if servo.reversed { -1.0 } else { 1.0 },
        f32::from(servo.centre_us),
        f32::from(servo.min_us),
        f32::from(servo.max_us),
        servo.throw_us,
    ]
}

/// The seven values of `entry`, in [`ENTRY_FIELDS`] order.
fn entry_values(entry: &TestEntry) -> [f32; ENTRY_FIELDS] {
    let axis = entry
        .axis
        .and_then(|a| Axis::ALL.iter().position(|x| *x == a))
        .map_or(0.0, |i| i as f32 + 1.0);
    let input = INPUTS.iter().position(|i| *i == entry.input).unwrap_or(0);
    [
        axis,
        input as f32,
        entry.omega_min,
        entry.omega_max,
        entry.pulse_width_s,
        entry.t_rec_s,
        entry.amplitude,
    ]
}
