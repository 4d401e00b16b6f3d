//! The world's obstacles as fixed rapier colliders, for the true flight (common.md §3: "the UAV's
//! collider touching world geometry ends the run as crashed").

use rapier3d::geometry::{ColliderBuilder, ColliderSet};
use uavex_components::world::WorldGeometry;

/// One fixed collider per obstacle, with the very shapes and poses the sensors see (parry's
/// shapes are shared, not copied). Each collider's `user_data` is the obstacle's index in
/// [`WorldGeometry::obstacles`], so a contact can name what the UAV hit.
pub fn colliders(world: &WorldGeometry) -> ColliderSet {
    let mut set = ColliderSet::new();
    for (index, obstacle) in world.obstacles().iter().enumerate() {
        set.insert(
            ColliderBuilder::new(obstacle.shape.clone())
                .position(obstacle.pose)
                .user_data(index as u128)
                .build(),
        );
    }
    set
}
