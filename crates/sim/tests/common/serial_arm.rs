//! A small serial flexible arm (test-only):  a planar chain of links on revolute-z
//! multibody joints, each driven through a drive spring (stiffness `k[i]`) whose rest angle is
//! the joint command. Its static tip compliance is `J K^-1 J^T` ([`SerialArmSim::linear_compliance`]).

use nalgebra::{DMatrix, Matrix2, Vector2};
use rapier3d_f64::prelude::*;

use deflect_sim::SimError;
use deflect_sim::rapier_util::{
    ANG_Z, body_point, insert_planar_chain, new_world, set_last_dof_damping, set_spring,
};
use deflect_sim::scenes::parallel::params::DT;

/// A planar serial arm with compliant joints in rapier.
pub struct SerialArmSim {
    world: PhysicsWorld,
    lengths: Vec<f64>,
    stiffness: Vec<f64>,
    q_ref: Vec<f64>,
    joints: Vec<MultibodyJointHandle>,
    tip_body: RigidBodyHandle,
}

impl core::fmt::Debug for SerialArmSim {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("SerialArmSim")
            .field("lengths", &self.lengths)
            .field("stiffness", &self.stiffness)
            .finish_non_exhaustive()
    }
}

impl SerialArmSim {
    /// Links of `lengths` \[m\] and `masses` \[kg\] (uniform rods), joint stiffnesses `stiffness`
    /// \[N m/rad\], built at absolute-relative joint angles `q` \[rad\].
    pub fn new(
        lengths: &[f64],
        masses: &[f64],
        stiffness: &[f64],
        q: &[f64],
    ) -> Result<Self, SimError> {
        let n = lengths.len();
        if masses.len() != n || stiffness.len() != n || q.len() != n || n == 0 {
            return Err(SimError::new("serial arm: inconsistent lengths"));
        }
        let mut world = new_world(Vector::ZERO, DT);
        let links: Vec<(f64, MassProperties)> = lengths
            .iter()
            .zip(masses)
            .map(|(&l, &m)| {
                let props = MassProperties::new(
                    Vector::new(0.5 * l, 0.0, 0.0),
                    m,
                    Vector::new(1e-5, m * l * l / 12.0, m * l * l / 12.0),
                );
                (l, props)
            })
            .collect();
        let (joints, bodies) = insert_planar_chain(
            &mut world,
            &links,
            q,
            "serial joint rejected",
            |world, h, i| {
                set_spring(world, h, ANG_Z, stiffness[i], 0.0);
                // structural damping [N m s/rad]: 10-40 % of critical for the default test arm
                set_last_dof_damping(world, h, 20.0);
            },
        )?;
        let tip_body = *bodies
            .last()
            .ok_or_else(|| SimError::new("serial arm: no links"))?;
        Ok(Self {
            world,
            lengths: lengths.to_vec(),
            stiffness: stiffness.to_vec(),
            q_ref: q.to_vec(),
            joints,
            tip_body,
        })
    }

    /// Tip position (x, y) \[m\].
    pub fn tip(&self) -> Vector2<f64> {
        let l = self.lengths.last().copied().unwrap_or(0.0);
        body_point(&self.world, self.tip_body, Vector::new(l, 0.0, 0.0)).xy()
    }

    /// One step with joint commands `q` \[rad\] (spring rest angles) and a tip force \[N\].
    pub fn step(&mut self, q: &[f64], force: &Vector2<f64>) {
        for (i, h) in self.joints.iter().enumerate() {
            let rest = q.get(i).copied().unwrap_or(0.0) - self.q_ref.get(i).copied().unwrap_or(0.0);
            set_spring(&mut self.world, *h, ANG_Z, self.stiffness[i], rest);
        }
        let tip = self.tip();
        if let Some(rb) = self.world.bodies.get_mut(self.tip_body) {
            rb.reset_forces(false);
            rb.reset_torques(false);
            rb.add_force_at_point(
                Vector::new(force.x, force.y, 0.0),
                Vector::new(tip.x, tip.y, 0.0),
                false,
            );
        }
        self.world.step();
    }

    /// `J K^-1 J^T` at the reference angles \[m/N\].
    pub fn linear_compliance(&self) -> Matrix2<f64> {
        let n = self.lengths.len();
        let mut j = DMatrix::zeros(2, n);
        let mut angles = Vec::with_capacity(n);
        let mut a = 0.0;
        for q in &self.q_ref {
            a += q;
            angles.push(a);
        }
        for i in 0..n {
            // Joint i moves links i.. : column = sum over k >= i of L_k * d/dangle (cos, sin).
            let (mut cx, mut cy) = (0.0, 0.0);
            for (l, a) in self.lengths.iter().zip(&angles).skip(i) {
                cx -= l * a.sin();
                cy += l * a.cos();
            }
            j[(0, i)] = cx;
            j[(1, i)] = cy;
        }
        let kinv = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(
            n,
            self.stiffness.iter().map(|k| 1.0 / k),
        ));
        let c = &j * kinv * j.transpose();
        Matrix2::new(c[(0, 0)], c[(0, 1)], c[(1, 0)], c[(1, 1)])
    }
}
