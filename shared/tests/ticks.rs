//! Tick accounting of the decoder: gaps counted on forward steps only, a tick that does not
//! move forward counted as a step back (never read as ~4·10⁹ missing ticks), and a wrap of
//! the u32 counter at 2³² read as the next tick.

use proptest::prelude::*;
use sweephold_protocol::{codec, synthetic, tick_step, DecodeStats, Decoder, Frame, TickStep};

fn stats_of(ticks: &[u32]) -> DecodeStats {
    let stream: Vec<u8> = ticks
        .iter()
        .flat_map(|&tick| {
            codec::encode_to_vec(&Frame::Sample(synthetic::sample(tick)))
                .unwrap()
                .to_vec()
        })
        .collect();
    let mut decoder = Decoder::new();
    assert_eq!(
        decoder.feed(&stream).filter(Result::is_ok).count(),
        ticks.len()
    );
    assert_eq!(decoder.finish(), None);
    decoder.stats()
}

#[test]
fn a_step_back_is_counted_and_is_no_gap() {
    let stats = stats_of(&[100, 101, 102, 50, 51]);
    assert_eq!((stats.tick_gaps, stats.tick_steps_back), (0, 1));
    // A step back then a jump forward: the jump's missing ticks are gaps.
    let stats = stats_of(&[100, 101, 102, 50, 55]);
    assert_eq!((stats.tick_gaps, stats.tick_steps_back), (4, 1));
}

#[test]
fn reversed_ticks_are_all_steps_back() {
    let ticks: Vec<u32> = (0..1000).rev().collect();
    let stats = stats_of(&ticks);
    assert_eq!((stats.tick_gaps, stats.tick_steps_back), (0, 999));
}

#[test]
fn a_repeated_tick_is_a_step_back() {
    let stats = stats_of(&[5, 5, 6]);
    assert_eq!((stats.tick_gaps, stats.tick_steps_back), (0, 1));
}

#[test]
fn the_counter_wrapping_at_2_pow_32_moves_forward() {
    let stats = stats_of(&[u32::MAX - 1, u32::MAX, 1, 2]);
    assert_eq!((stats.tick_gaps, stats.tick_steps_back), (1, 0));
    assert_eq!(tick_step(u32::MAX, 0), TickStep::Forward(1));
    assert_eq!(tick_step(0, u32::MAX), TickStep::Back);
    // The boundary: a forward distance below 2³¹ is forward, from 2³¹ on it is a step back.
    assert_eq!(
        tick_step(0, (1 << 31) - 1),
        TickStep::Forward((1 << 31) - 1)
    );
    assert_eq!(tick_step(0, 1 << 31), TickStep::Back);
    assert_eq!(tick_step(7, 7), TickStep::Back);
}

#[derive(Clone, Copy, Debug)]
enum Step {
    Forward(u32),
    Back(u32),
}

fn step() -> impl Strategy<Value = Step> {
    prop_oneof![
        4 => (1u32..1000).prop_map(Step::Forward),
        1 => (0u32..1000).prop_map(Step::Back),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    /// Any walk of the counter — forward steps of 1..1000, steps back (or repeats) of
    /// 0..1000, anywhere in the u32 range so that some walks wrap — gives exactly the
    /// gaps of its forward steps and one count per step back.
    #[test]
    fn gaps_and_steps_back_match_the_walk(start in any::<u32>(),
                                          steps in proptest::collection::vec(step(), 0..200)) {
        let mut ticks = vec![start];
        let (mut gaps, mut back) = (0u64, 0u64);
        for step in &steps {
            let last = *ticks.last().unwrap();
            ticks.push(match *step {
                Step::Forward(n) => {
                    gaps += u64::from(n - 1);
                    last.wrapping_add(n)
                }
                Step::Back(n) => {
                    back += 1;
                    last.wrapping_sub(n)
                }
            });
        }
        let stats = stats_of(&ticks);
        prop_assert_eq!(stats.tick_gaps, gaps);
        prop_assert_eq!(stats.tick_steps_back, back);
    }
}
