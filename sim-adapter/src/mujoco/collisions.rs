//! Leg contacts with the terrain other than the soles': a shin that hits a stair's nosing, a knee
//! that scrapes a riser. Counted as events, a leg capsule (`mjcf`'s leg bones) touching the floor
//! or a surface box in a physics step after touching neither in the step before, so a walk can
//! say how often its legs hit the terrain and where.

use std::sync::Arc;

use mujoco_rs::prelude::{MjData, MjModel, MjtObjBase};

use super::mjcf;

/// How many events [`TerrainCollisions::first`] keeps.
pub const KEPT_EVENTS: usize = 8;

/// One leg capsule starting to touch the terrain.
#[derive(Clone, Debug, PartialEq)]
pub struct TerrainCollision {
    /// Simulated time of the physics step it began in (s).
    pub time_s: f64,
    /// The leg link whose capsule touched (the link a `legs` joint moves: a thigh, a shin).
    pub link: Arc<str>,
    /// What it touched: the scene surface's name, or `floor` (the plane around the scene).
    pub surface: Arc<str>,
}

/// The leg contacts of a run so far: kept from the simulator's construction on (one simulator
/// per walk), like its safety summary and motor load.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TerrainCollisions {
    /// Number of events: a leg capsule touching the terrain after touching nothing in the
    /// previous physics step.
    pub count: u64,
    /// The first [`KEPT_EVENTS`] events, in order.
    pub first: Vec<TerrainCollision>,
}

/// Watches the contact list for leg-terrain contacts. Allocation-free after construction.
#[derive(Debug)]
pub(crate) struct CollisionWatch {
    /// Per geom id: its index among the leg capsules, if it is one.
    leg_of_geom: Vec<Option<usize>>,
    /// Per geom id: the name of the terrain it is (a surface or the floor), if it is terrain.
    terrain_of_geom: Vec<Option<Arc<str>>>,
    /// Link of each leg capsule.
    leg_links: Vec<Arc<str>>,
    /// The terrain geom each leg capsule touched in the last observed step, if any.
    touching: Vec<Option<usize>>,
    /// The same for the step being observed.
    now: Vec<Option<usize>>,
    record: TerrainCollisions,
}

impl CollisionWatch {
    /// Finds the leg capsules (by name) and the terrain (the world's geoms on the ground bit) in
    /// `model`; a model without leg capsules gives a watch that never counts.
    pub fn new(model: &MjModel) -> Self {
        let geoms = model.ngeom() as usize;
        let (bodies, contype) = (model.geom_bodyid(), model.geom_contype());
        let name = |kind, id| model.id_to_name(kind, id).unwrap_or_default();
        let mut watch = Self {
            leg_of_geom: vec![None; geoms],
            terrain_of_geom: vec![None; geoms],
            leg_links: Vec::new(),
            touching: Vec::new(),
            now: Vec::new(),
            record: TerrainCollisions {
                count: 0,
                first: Vec::with_capacity(KEPT_EVENTS),
            },
        };
        for geom in 0..geoms {
            let geom_name = name(MjtObjBase::mjOBJ_GEOM, geom);
            if geom_name.starts_with(mjcf::LEG_PREFIX) {
                watch.leg_of_geom[geom] = Some(watch.leg_links.len());
                let link = name(MjtObjBase::mjOBJ_BODY, bodies[geom] as usize);
                watch.leg_links.push(Arc::from(link));
            } else if bodies[geom] == 0 && contype[geom] as u32 & mjcf::GROUND_BIT != 0 {
                let surface = geom_name
                    .strip_prefix(mjcf::SURFACE_PREFIX)
                    .unwrap_or(geom_name);
                watch.terrain_of_geom[geom] = Some(Arc::from(surface));
            }
        }
        watch.touching = vec![None; watch.leg_links.len()];
        watch.now = vec![None; watch.leg_links.len()];
        watch
    }

    /// Reads the contact list of the state `data` was last evaluated in (at `time_s`) and records
    /// each leg capsule that began touching the terrain.
    pub fn observe(&mut self, data: &MjData<Box<MjModel>>, time_s: f64) {
        if self.leg_links.is_empty() {
            return;
        }
        self.now.fill(None);
        for contact in data.contact() {
            let [a, b] = contact.geom.map(|g| g as usize);
            let (leg, other) = match (self.leg_of_geom[a], self.leg_of_geom[b]) {
                (Some(leg), None) => (leg, b),
                (None, Some(leg)) => (leg, a),
                _ => continue,
            };
            if self.terrain_of_geom[other].is_some() {
                self.now[leg].get_or_insert(other);
            }
        }
        for (leg, (now, before)) in self.now.iter().zip(&self.touching).enumerate() {
            let (Some(terrain), None) = (now, before) else {
                continue;
            };
            self.record.count += 1;
            if self.record.first.len() < KEPT_EVENTS {
                self.record.first.push(TerrainCollision {
                    time_s,
                    link: Arc::clone(&self.leg_links[leg]),
                    surface: self.terrain_of_geom[*terrain]
                        .clone()
                        .expect("a terrain geom"),
                });
            }
        }
        std::mem::swap(&mut self.now, &mut self.touching);
    }

    /// Whether geom `id` is a leg capsule.
    #[cfg(test)]
    pub fn is_leg(&self, id: usize) -> bool {
        self.leg_of_geom[id].is_some()
    }

    /// The events so far.
    pub fn record(&self) -> &TerrainCollisions {
        &self.record
    }
}
