use super::*;
use crate::exploration::strategy::classic::largest_gain;
use crate::exploration::strategy::eaae::least_energy_among_largest_gain;
use crate::exploration::strategy::nearest::nearest;
use crate::exploration::strategy::tour::{
    first_of_least_energy_tour, first_of_tour_among_largest_gain,
};
use glam::Vec3;
use uavex_components::exploration::{Chosen, For, NeedsDecision};

fn view(index: u32, gain: u32, distance: f32, energy: f64) -> CandidateView {
    CandidateView {
        entity: Entity::from_raw_u32(index + 1).unwrap(),
        goal: Vec3::new(distance, 0.0, 0.0),
        information_gain: gain,
        centroid_distance_m: distance,
        path_length_m: distance,
        energy_j: energy,
        duration_s: energy / 100.0,
    }
}

/// Four candidates: gains 50, 400, 300, 200; distances 3, 9, 6, 2.5; energies 300, 1100, 700, 250.
fn four() -> Vec<CandidateView> {
    vec![
        view(0, 50, 3.0, 300.0),
        view(1, 400, 9.0, 1100.0),
        view(2, 300, 6.0, 700.0),
        view(3, 200, 2.5, 250.0),
    ]
}

#[test]
fn each_strategy_picks_by_its_own_rule() {
    let c = four();
    // Classic: largest IG (400).
    assert_eq!(largest_gain(&c), Some(c[1].entity));
    // Nearest: 2.5 m.
    assert_eq!(nearest(&c), Some(c[3].entity));
    // EAAE, N = 3: IG 400, 300, 200 shortlisted; least energy among them is 250 J (IG 200).
    assert_eq!(
        least_energy_among_largest_gain(&c, Some(3)),
        Some(c[3].entity)
    );
    // N = 2: only IG 400 and 300; 700 J wins.
    assert_eq!(
        least_energy_among_largest_gain(&c, Some(2)),
        Some(c[2].entity)
    );
    // All: the 50-voxel cluster is not cheaper than 250 J, so still the IG-200 one.
    assert_eq!(least_energy_among_largest_gain(&c, None), Some(c[3].entity));
    // Nothing to choose from: no choice.
    assert_eq!(least_energy_among_largest_gain(&[], None), None);
    assert_eq!(largest_gain(&[]), None);
}

/// Clusters on a line through the UAV, one 1.5 m behind and five ahead from 1 m on, each
/// predicted at 100 J/m: EAAE takes the nearest ahead (100 J) and must come back past the UAV
/// for the one behind in the end (1,150 J in all); the tour takes the one behind first (800 J).
#[test]
fn the_tour_takes_the_cluster_behind_first() {
    let xs = [1.0f32, 2.0, 3.0, 4.0, 5.0, -1.5];
    let c: Vec<CandidateView> = (xs.iter().enumerate())
        .map(|(i, &x)| CandidateView {
            goal: Vec3::new(x, 0.0, 0.0),
            ..view(i as u32, 100, x.abs(), 100.0 * f64::from(x.abs()))
        })
        .collect();
    assert_eq!(least_energy_among_largest_gain(&c, None), Some(c[0].entity));
    assert_eq!(first_of_least_energy_tour(&c), Some(c[5].entity));
    assert_eq!(
        first_of_tour_among_largest_gain(&c, None),
        Some(c[5].entity)
    );
    // The cluster behind with the least gain and a shortlist of five: it is not a stop, and
    // the tour of the five ahead starts at the nearest.
    let mut small_behind = c.clone();
    small_behind[5].information_gain = 10;
    assert_eq!(
        first_of_tour_among_largest_gain(&small_behind, Some(5)),
        Some(c[0].entity)
    );
    assert_eq!(
        first_of_tour_among_largest_gain(&small_behind, Some(6)),
        Some(c[5].entity)
    );
    // One candidate or none: no tour to weigh.
    assert_eq!(first_of_least_energy_tour(&c[..1]), Some(c[0].entity));
    assert_eq!(first_of_least_energy_tour(&[]), None);
}

#[test]
fn ties_keep_the_first_candidate() {
    let c = vec![view(0, 100, 4.0, 500.0), view(1, 100, 4.0, 500.0)];
    assert_eq!(largest_gain(&c), Some(c[0].entity));
    assert_eq!(nearest(&c), Some(c[0].entity));
    assert_eq!(
        least_energy_among_largest_gain(&c, Some(1)),
        Some(c[0].entity)
    );
}

/// The strategies as systems: each UAV gets the pick of the strategy it carries; an
/// unaffordable candidate is never chosen.
#[test]
fn strategy_systems_mark_their_own_uavs() {
    let mut world = World::new();
    let spawn_uav = |world: &mut World, marker: &dyn Fn(&mut EntityWorldMut)| {
        let mut uav = world.spawn(NeedsDecision);
        marker(&mut uav);
        let uav = uav.id();
        let mut ids = Vec::new();
        for (gain, distance, energy, unaffordable) in [
            (400u32, 9.0f32, 1100.0, false),
            (200, 2.5, 250.0, true),
            (300, 6.0, 700.0, false),
        ] {
            let mut c = world.spawn((
                CandidateTrajectory {
                    trajectory: std::sync::Arc::new(
                        uavex_components::trajectory::PiecewisePolynomial::new(vec![
                            uavex_components::trajectory::PolynomialSegment {
                                duration: 1.0,
                                coefficients: Default::default(),
                            },
                        ])
                        .unwrap(),
                    ),
                    goal: glam::Vec3::new(distance, 0.0, 0.0),
                    goal_yaw: 0.0,
                    information_gain: gain,
                    centroid_distance_m: distance,
                    path_length_m: distance,
                    viewpoint: None,
                },
                For(uav),
                PredictedEnergy(energy),
                PredictedDuration(1.0),
            ));
            if unaffordable {
                c.insert(Unaffordable {
                    return_energy_j: 1e9,
                });
            }
            ids.push(c.id());
        }
        (uav, ids)
    };
    let (eaae, eaae_c) = spawn_uav(&mut world, &|u| {
        u.insert(EaaeStrategy { shortlist: None });
    });
    let (classic, classic_c) = spawn_uav(&mut world, &|u| {
        u.insert(ClassicStrategy);
    });
    let (near, near_c) = spawn_uav(&mut world, &|u| {
        u.insert(NearestStrategy);
    });
    let (tour, tour_c) = spawn_uav(&mut world, &|u| {
        u.insert(TourStrategy { shortlist: None });
    });
    let mut schedule = Schedule::default();
    schedule.add_systems((
        choose_least_energy,
        choose_largest_gain,
        choose_nearest,
        choose_by_tour,
    ));
    schedule.run(&mut world);
    // The 250 J / 2.5 m candidate is unaffordable: EAAE takes 700 J, Nearest 6 m.
    assert_eq!(world.get::<Chosen>(eaae), Some(&Chosen(eaae_c[2])));
    // Tour: 700 J, then 3 m at 120 J/m (1,800 J over 15 m), against 1,100 J and 3 m back.
    assert_eq!(world.get::<Chosen>(tour), Some(&Chosen(tour_c[2])));
    assert_eq!(world.get::<Chosen>(classic), Some(&Chosen(classic_c[0])));
    assert_eq!(world.get::<Chosen>(near), Some(&Chosen(near_c[2])));
}
