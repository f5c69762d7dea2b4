//! The paper's D'Alembert corrector (Paksoy, Dede and Kiper 2025, "Enhancing
//! trajectory-tracking accuracy of high-acceleration parallel robots by predicting compliant
//! displacements", sections 2-3.3 and Fig. 2): the planned acceleration `a` of the end
//! effector gives the D'Alembert force `F_D = -m* a` (Eq. 5), a compliance model predicts the
//! displacement that force causes at the planned position (Eq. 9-14), the commanded point is
//! the desired point minus that displacement, and inverse kinematics turns it into joint
//! commands, every servo tick (2 kHz in the paper).
//!
//! Beyond the paper, the command can be iterated to a fixed point `c = x_d - d(c, F_D)`: the
//! compliance model is then evaluated where the robot is actually sent, not where the path
//! is. With `iterations = 0` the corrector is exactly the paper's one-shot update.
//!
//! The corrector is generic over the robot ([`Mechanism`], closed-form or iterative IK of a
//! task point) and over the compliance model ([`DisplacementModel`]; the paper's compliance
//! map is one). The paper's paths are pure translations of a parallel robot's platform, so
//! the D'Alembert load is a force and no moment (Euler's part of Eq. 3) arises; a serial arm
//! moving a payload through a 6-D pose uses [`super::serial`].
//!
//! The tick shape: a [`Model`] (mechanism, compliance model, mass parameter, fixed-point
//! settings) validated once, a [`Data`] holding both pieces' workspaces and the last tick's
//! joints (the next tick's IK seed), and [`step`]. Every per-tick function allocates nothing,
//! runs in bounded time (at most `1 + iterations` model evaluations and as many IK solves)
//! and never panics.
//!
//! ```
//! use deflect_core::compliance_map::ComplianceMap;
//! use deflect_core::dalembert::parallel::{self, Data, Model};
//! use deflect_core::mechanism::ParallelRobot2;
//! use nalgebra::Vector2;
//! // A uniform map over the paper's workspace: 1 um/N along both axes, no cross terms.
//! let (x, y) = (vec![0.15, 0.30], vec![-0.12, 0.12]);
//! let slopes = [1e-6, 0.0, 0.0, 1e-6].repeat(4);
//! let map = ComplianceMap::new(x, y, 2, 2, slopes, vec![0.0; 16])?;
//! let model = Model::new(ParallelRobot2::paper(), map, parallel::PAPER_MASS)?;
//! let mut data = Data::new(&model);
//! // 5 g along +y at (0.22, 0): F = -m* a = -245 N along y, predicted 0.245 mm, pre-compensated.
//! let tick = parallel::step(&model, &mut data, &Vector2::new(0.22, 0.0),
//!                           &Vector2::new(0.0, 5.0 * 9.81))?;
//! assert!((tick.commanded.y - 2.4525e-4).abs() < 1e-12);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use nalgebra::{SVector, Vector2};

#[cfg(feature = "alloc")]
use crate::compliance_map::ComplianceMap;
use crate::compliance_map::ComplianceMapView;
use crate::error::{BuildError, Placement, TickError, check_finite, param};
use crate::mechanism::Mechanism;
use crate::motion::Trajectory;

/// A compliance model the corrector can query: the static displacement \[m\] of the task point
/// at `position` \[m\] (robot at joints `q`) under the force `force` \[N\] acting there.
pub trait DisplacementModel<const T: usize, const J: usize> {
    /// Per-call workspace (`()` for a compliance map, the chain's [`crate::vjm::Data`] for the
    /// virtual-joint model). Made once, outside the tick.
    type Data;

    /// A workspace for this model.
    fn new_data(&self) -> Self::Data;

    /// Checks once, when the corrector is built, that the model fits the corrector's
    /// dimensions.
    fn check(&self) -> Result<(), BuildError> {
        Ok(())
    }

    /// The displacement and where the query fell.
    fn displacement(
        &self,
        data: &mut Self::Data,
        position: &SVector<f64, T>,
        q: &SVector<f64, J>,
        force: &SVector<f64, T>,
    ) -> Result<(SVector<f64, T>, Placement), TickError>;

    /// Whether [`Self::displacement`] reads `q` (then the corrector solves IK before each
    /// evaluation; a compliance map depends on the position only).
    fn needs_joints(&self) -> bool {
        false
    }
}

/// The paper's compliance map (2 force axes, 2 displacement axes over the (x, y) grid) with
/// the query options stored in the view.
impl<const J: usize> DisplacementModel<2, J> for ComplianceMapView<'_> {
    type Data = ();

    fn new_data(&self) {}

    fn check(&self) -> Result<(), BuildError> {
        if self.n_force() != 2 || self.n_displacement() != 2 {
            return Err(BuildError::MapDimension {
                expected: 2,
                n_force: self.n_force(),
                n_displacement: self.n_displacement(),
            });
        }
        Ok(())
    }

    fn displacement(
        &self,
        _data: &mut (),
        position: &Vector2<f64>,
        _q: &SVector<f64, J>,
        force: &Vector2<f64>,
    ) -> Result<(Vector2<f64>, Placement), TickError> {
        // Checked when the corrector was built; repeated here because knowing the map is
        // 2 x 2 lets the compiler specialise the lookup (about 20 ns of a 100 ns tick).
        if self.n_force() != 2 || self.n_displacement() != 2 {
            return Err(TickError::WrongLength {
                what: "map axes (force and displacement)",
                expected: 2,
                got: self.n_force().max(self.n_displacement()),
            });
        }
        let mut out = [0.0; 2];
        let placement = self.displacement_with(
            [position.x, position.y],
            force.as_slice(),
            &mut out,
            self.options(),
        )?;
        Ok((Vector2::new(out[0], out[1]), placement))
    }
}

/// The owning map, queried through its view with its default options.
#[cfg(feature = "alloc")]
impl<const J: usize> DisplacementModel<2, J> for ComplianceMap {
    type Data = ();

    fn new_data(&self) {}

    fn check(&self) -> Result<(), BuildError> {
        <ComplianceMapView<'_> as DisplacementModel<2, J>>::check(&self.view())
    }

    #[inline]
    fn displacement(
        &self,
        data: &mut (),
        position: &Vector2<f64>,
        q: &SVector<f64, J>,
        force: &Vector2<f64>,
    ) -> Result<(Vector2<f64>, Placement), TickError> {
        <ComplianceMapView<'_> as DisplacementModel<2, J>>::displacement(
            &self.view(),
            data,
            position,
            q,
            force,
        )
    }
}

/// A 3-D grid map over the task space `(x, y, z)` with 3 force and 3 displacement axes (a
/// Delta robot's), queried with its default options.
#[cfg(feature = "alloc")]
impl<const J: usize> DisplacementModel<3, J> for crate::compliance_map::GridMap {
    type Data = ();

    fn new_data(&self) {}

    fn check(&self) -> Result<(), BuildError> {
        if self.dims() != 3 {
            return Err(BuildError::InvalidParameter {
                what: "grid dimensions of a task-space map for a 3-D corrector",
                value: self.dims() as f64,
                expected: "3 (x, y, z)",
            });
        }
        if self.n_force() != 3 || self.n_displacement() != 3 {
            return Err(BuildError::MapDimension {
                expected: 3,
                n_force: self.n_force(),
                n_displacement: self.n_displacement(),
            });
        }
        Ok(())
    }

    fn displacement(
        &self,
        _data: &mut (),
        position: &nalgebra::Vector3<f64>,
        _q: &SVector<f64, J>,
        force: &nalgebra::Vector3<f64>,
    ) -> Result<(nalgebra::Vector3<f64>, Placement), TickError> {
        let mut out = [0.0; 3];
        let placement = self.displacement(position.as_slice(), force.as_slice(), &mut out)?;
        Ok((nalgebra::Vector3::from(out), placement))
    }
}

/// What the paper's corrector reports beyond the common [`Tick`] fields.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Diagnostics {
    /// `|c_k - c_(k-1)|` of the last fixed-point iteration \[m\] (0 without iterations).
    pub fixed_point_residual: f64,
    /// Worst placement of the compliance-model queries of the tick.
    pub placement: Placement,
}

/// One corrected tick of a robot with `T` task and `J` joint coordinates: desired and
/// commanded task points \[m\], joint command \[rad or m\], the D'Alembert force `-m* a` \[N\]
/// (Eq. 5) as the load, the predicted displacement at the commanded point \[m\], the
/// fixed-point iterations done (0 = the paper's one-shot update) and [`Diagnostics`].
pub type Tick<const T: usize, const J: usize> =
    super::Tick<SVector<f64, T>, SVector<f64, T>, SVector<f64, J>, Diagnostics>;

/// The D'Alembert corrector of one robot: its mechanism, compliance model, mass parameter m*
/// and fixed-point settings, validated once. Immutable.
#[derive(Debug, Clone, PartialEq)]
pub struct Model<M, D> {
    mechanism: M,
    compliance: D,
    mass: f64,
    iterations: usize,
    tolerance: f64,
}

/// The paper's tuned mass parameter m* \[kg\] for its 3.6 kg platform (section 5.1).
pub const PAPER_MASS: f64 = 5.0;

/// Most fixed-point iterations a corrector may do per tick: the iteration contracts by the
/// map's compliance slope (about 1e-3), so 3 reach rounding; 64 bounds the tick's time.
pub const MAX_FIXED_POINT_ITERATIONS: usize = 64;

impl<M, D> Model<M, D> {
    /// The corrector of `mechanism` with the compliance model `compliance` and mass parameter
    /// `mass` \[kg\] (m* of the paper, finite and >= 0): the paper's one-shot update.
    pub fn new<const T: usize, const J: usize>(
        mechanism: M,
        compliance: D,
        mass: f64,
    ) -> Result<Self, BuildError>
    where
        M: Mechanism<T, J>,
        D: DisplacementModel<T, J>,
    {
        compliance.check()?;
        param("mass", mass, mass >= 0.0, "finite and >= 0 (kg)")?;
        Ok(Self {
            mechanism,
            compliance,
            mass,
            iterations: 0,
            tolerance: 0.0,
        })
    }

    /// Iterate `c = x_d - d(c, F)` at most `iterations` times, stopping once successive
    /// commands differ by at most `tolerance` \[m\] (finite, >= 0). Bounded: each iteration
    /// costs one model evaluation (plus one IK for models that read the joints).
    pub fn with_fixed_point(
        mut self,
        iterations: usize,
        tolerance: f64,
    ) -> Result<Self, BuildError> {
        self.tolerance = param(
            "tolerance",
            tolerance,
            tolerance >= 0.0,
            "finite and >= 0 (m)",
        )?;
        if iterations > MAX_FIXED_POINT_ITERATIONS {
            return Err(BuildError::Budget {
                what: "fixed-point iterations",
                budget: "MAX_FIXED_POINT_ITERATIONS",
                limit: MAX_FIXED_POINT_ITERATIONS,
                requested: iterations,
            });
        }
        self.iterations = iterations;
        Ok(self)
    }

    /// Mass parameter m* \[kg\].
    pub fn mass(&self) -> f64 {
        self.mass
    }
    /// Most fixed-point iterations.
    pub fn iterations(&self) -> usize {
        self.iterations
    }
    /// Fixed-point tolerance \[m\].
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }
    /// The mechanism.
    pub fn mechanism(&self) -> &M {
        &self.mechanism
    }
    /// The compliance model.
    pub fn compliance(&self) -> &D {
        &self.compliance
    }
}

/// The corrector's workspaces and the last tick's joints, which seed the next tick's IK.
#[derive(Debug, Clone)]
pub struct Data<MD, DD, const J: usize> {
    mechanism: MD,
    compliance: DD,
    /// Joints of the last tick (zeros until the first tick or [`Self::set_seed`]): the seed
    /// of the next iterative IK.
    pub joints: SVector<f64, J>,
}

impl<MD, DD, const J: usize> Data<MD, DD, J> {
    /// Workspaces for `model`; the IK seed starts at zero joints.
    pub fn new<M, D, const T: usize>(model: &Model<M, D>) -> Self
    where
        M: Mechanism<T, J, Data = MD>,
        D: DisplacementModel<T, J, Data = DD>,
    {
        Self {
            mechanism: model.mechanism.new_data(),
            compliance: model.compliance.new_data(),
            joints: SVector::zeros(),
        }
    }

    /// Sets the joints the next tick's IK starts from (e.g. the robot's joints at the start
    /// of a motion) \[rad or m\].
    pub fn set_seed(&mut self, joints: SVector<f64, J>) {
        self.joints = joints;
    }
}

/// One tick: desired point `desired` \[m\] with planned acceleration `acceleration` \[m/s^2\].
/// The IK starts from `data.joints` (the previous tick's; ignored by closed-form IK) and
/// leaves this tick's joints there.
pub fn step<M, D, const T: usize, const J: usize>(
    model: &Model<M, D>,
    data: &mut Data<M::Data, D::Data, J>,
    desired: &SVector<f64, T>,
    acceleration: &SVector<f64, T>,
) -> Result<Tick<T, J>, TickError>
where
    M: Mechanism<T, J>,
    D: DisplacementModel<T, J>,
{
    check_finite("position", desired.as_slice())?;
    check_finite("acceleration", acceleration.as_slice())?;
    let (mech, disp_model) = (&model.mechanism, &model.compliance);
    let seed = data.joints;
    // Eq. 5: the D'Alembert force of the tuned mass.
    let force = acceleration * (-model.mass);
    let needs_q = disp_model.needs_joints();
    // The paper's update: the model evaluated at the desired point.
    let mut q = if needs_q {
        mech.inverse(&mut data.mechanism, desired, &seed)?
    } else {
        seed
    };
    let (mut disp, mut placement) =
        disp_model.displacement(&mut data.compliance, desired, &q, &force)?;
    let mut commanded = desired - disp;
    let mut residual = 0.0;
    let mut iterations = 0;
    while iterations < model.iterations {
        if needs_q {
            q = mech.inverse(&mut data.mechanism, &commanded, &q)?;
        }
        let (d, s) = disp_model.displacement(&mut data.compliance, &commanded, &q, &force)?;
        placement = placement.worst(s);
        let next = desired - d;
        let previous = residual;
        residual = (next - commanded).norm();
        commanded = next;
        disp = d;
        iterations += 1;
        // Stop at the tolerance, or once the iteration stops contracting (rounding).
        if residual <= model.tolerance || (iterations > 1 && residual >= previous) {
            break;
        }
    }
    let ik_seed = if needs_q { q } else { seed };
    let joints = mech.inverse(&mut data.mechanism, &commanded, &ik_seed)?;
    crate::error::check_output("joints", joints.as_slice())?;
    data.joints = joints;
    Ok(Tick {
        desired: *desired,
        commanded,
        joints,
        load: force,
        displacement: disp,
        iterations,
        diagnostics: Diagnostics {
            fixed_point_residual: residual,
            placement,
        },
    })
}

/// Corrects a whole planned trajectory sampled at `rate_hz`, handing every tick to `sink` in
/// order. Uses [`step`] tick by tick (each IK seeded by the previous tick), so it agrees
/// exactly with a streaming loop; the first tick starts from `data.joints`. Allocation-free.
pub fn correct_each<M, D, const T: usize, const J: usize>(
    model: &Model<M, D>,
    data: &mut Data<M::Data, D::Data, J>,
    trajectory: &Trajectory<T>,
    rate_hz: f64,
    mut sink: impl FnMut(usize, &Tick<T, J>),
) -> Result<usize, TickError>
where
    M: Mechanism<T, J>,
    D: DisplacementModel<T, J>,
{
    let mut n = 0;
    for state in trajectory.ticks(rate_hz)? {
        let tick = step(model, data, &state.position, &state.acceleration)?;
        sink(n, &tick);
        n += 1;
    }
    Ok(n)
}

/// [`correct_each`] collected into a vector (needs `alloc`); at most
/// [`crate::motion::MAX_SAMPLES`] ticks ([`TickError::Budget`] past it).
#[cfg(feature = "alloc")]
pub fn correct<M, D, const T: usize, const J: usize>(
    model: &Model<M, D>,
    data: &mut Data<M::Data, D::Data, J>,
    trajectory: &Trajectory<T>,
    rate_hz: f64,
) -> Result<alloc::vec::Vec<Tick<T, J>>, TickError>
where
    M: Mechanism<T, J>,
    D: DisplacementModel<T, J>,
{
    let mut out = alloc::vec::Vec::with_capacity(trajectory.sample_count(rate_hz)?);
    correct_each(model, data, trajectory, rate_hz, |_, t| out.push(*t))?;
    Ok(out)
}
