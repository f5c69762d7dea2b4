//! The immutable chain model, its builder and the per-call workspace.

use nalgebra::{Isometry3, Matrix6, SMatrix, Unit, Vector3};

use crate::error::BuildError;

/// Most actuated joints a model may have: a 6-axis arm plus a linear track and a turntable,
/// the largest cell the machining papers consider. Sizes the fixed Jacobian in [`Data`].
pub const MAX_DOF: usize = 8;
/// Most virtual joints: the paper's KR 300 model has 11 (Table 1); 32 leaves room for a
/// spring per joint and per link of an 8-axis cell with a multi-part end effector.
pub const MAX_SPRINGS: usize = 32;
/// Most chain elements after merging consecutive fixed transforms. A spring placed inside a
/// link costs up to three elements (offset, spring, inverse offset), a joint two; 4 * 32
/// covers [`MAX_SPRINGS`] springs and [`MAX_DOF`] joints with their fixed origins.
pub const MAX_ELEMENTS: usize = 128;

/// One link of the kinematic chain, applied left to right from the base to the TCP.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Element {
    /// A constant transform (URDF joint origins, fixed joints, tool offsets).
    Fixed(Isometry3<f64>),
    /// A revolute joint about `axis` of the current frame; angle `q[index]` [rad].
    Revolute {
        /// Unit axis in the current frame.
        axis: Unit<Vector3<f64>>,
        /// Index into the joint vector.
        index: usize,
    },
    /// A prismatic joint along `axis` of the current frame; travel `q[index]` [m].
    Prismatic {
        /// Unit axis in the current frame.
        axis: Unit<Vector3<f64>>,
        /// Index into the joint vector.
        index: usize,
    },
    /// A virtual joint at the current frame: compliances `1/k` [rad / (N m)] about the frame's
    /// x, y, z axes (k_C, k_B, k_A of Table 1). A compliance of 0 is a rigid axis.
    Spring {
        /// `[1/k_C, 1/k_B, 1/k_A]` [rad / (N m)].
        compliance: Vector3<f64>,
        /// Index of the spring in chain order.
        index: usize,
    },
}

/// An immutable serial chain with virtual joints, built once by [`ModelBuilder`] or loaded by
/// [`crate::SerialRobot`]. Holds no heap memory, so it can live in a static on a controller.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    pub(crate) elements: heapless::Vec<Element, MAX_ELEMENTS>,
    pub(crate) dof: usize,
    pub(crate) springs: usize,
}

impl Model {
    /// Number of actuated joints (length of `q`).
    pub fn dof(&self) -> usize {
        self.dof
    }
    /// Number of virtual joints.
    pub fn spring_count(&self) -> usize {
        self.springs
    }
    /// The chain, base to TCP.
    pub fn elements(&self) -> &[Element] {
        &self.elements
    }
}

/// Builds a [`Model`] element by element, without a heap.
///
/// ```
/// use deflect_core::ModelBuilder;
/// use nalgebra::{Isometry3, Vector3};
/// // A 1 m arm about z, with one spring at the joint that is soft about z.
/// let model = ModelBuilder::new()
///     .revolute(Vector3::z())?
///     .spring([f64::INFINITY, f64::INFINITY, 1.0e4])?
///     .fixed(Isometry3::translation(1.0, 0.0, 0.0))?
///     .build()?;
/// assert_eq!(model.dof(), 1);
/// # Ok::<(), deflect_core::BuildError>(())
/// ```
#[derive(Debug, Clone, Default)]
pub struct ModelBuilder {
    elements: heapless::Vec<Element, MAX_ELEMENTS>,
    dof: usize,
    springs: usize,
    calls: usize,
}

impl ModelBuilder {
    /// An empty chain (the TCP is the base frame).
    pub fn new() -> Self {
        Self::default()
    }

    fn push(&mut self, e: Element) -> Result<(), BuildError> {
        self.elements
            .push(e)
            .map_err(|_| BuildError::CapacityExceeded {
                what: "elements",
                capacity: MAX_ELEMENTS,
            })
    }

    /// Appends a constant transform (merged with a preceding one).
    pub fn fixed(mut self, t: Isometry3<f64>) -> Result<Self, BuildError> {
        let element = self.calls;
        self.calls += 1;
        if !iso_is_finite(&t) {
            return Err(BuildError::NonFiniteTransform { element });
        }
        if let Some(Element::Fixed(prev)) = self.elements.last_mut() {
            *prev *= t;
        } else {
            self.push(Element::Fixed(t))?;
        }
        Ok(self)
    }

    fn joint(mut self, axis: Vector3<f64>, revolute: bool) -> Result<Self, BuildError> {
        let element = self.calls;
        self.calls += 1;
        let norm = axis.norm();
        if !(norm.is_finite() && norm > 0.0) {
            return Err(BuildError::ZeroAxis { element });
        }
        if self.dof >= MAX_DOF {
            return Err(BuildError::CapacityExceeded {
                what: "joints",
                capacity: MAX_DOF,
            });
        }
        let axis = Unit::new_normalize(axis);
        let index = self.dof;
        self.push(if revolute {
            Element::Revolute { axis, index }
        } else {
            Element::Prismatic { axis, index }
        })?;
        self.dof += 1;
        Ok(self)
    }

    /// Appends a revolute joint about `axis` (any non-zero length) of the current frame.
    pub fn revolute(self, axis: Vector3<f64>) -> Result<Self, BuildError> {
        self.joint(axis, true)
    }

    /// Appends a prismatic joint along `axis` (any non-zero length) of the current frame.
    pub fn prismatic(self, axis: Vector3<f64>) -> Result<Self, BuildError> {
        self.joint(axis, false)
    }

    /// Appends a virtual joint at the current frame with stiffnesses `k = [k_C, k_B, k_A]`
    /// [N m / rad] about its x, y, z axes; `f64::INFINITY` makes an axis rigid.
    pub fn spring(mut self, k: [f64; 3]) -> Result<Self, BuildError> {
        let element = self.calls;
        self.calls += 1;
        let mut compliance = Vector3::zeros();
        for (axis, (&ki, ci)) in k.iter().zip(compliance.iter_mut()).enumerate() {
            if ki.is_nan() || ki <= 0.0 {
                return Err(BuildError::NonPositiveStiffness {
                    element,
                    axis,
                    value: ki,
                });
            }
            *ci = 1.0 / ki; // 0 for +inf: rigid
        }
        if self.springs >= MAX_SPRINGS {
            return Err(BuildError::CapacityExceeded {
                what: "springs",
                capacity: MAX_SPRINGS,
            });
        }
        let index = self.springs;
        self.push(Element::Spring { compliance, index })?;
        self.springs += 1;
        Ok(self)
    }

    /// Appends a virtual joint whose frame sits at `frame` relative to the current frame
    /// (an offset and orientation inside a link); the chain continues from the current frame.
    pub fn spring_at(self, frame: Isometry3<f64>, k: [f64; 3]) -> Result<Self, BuildError> {
        if frame == Isometry3::identity() {
            return self.spring(k);
        }
        self.fixed(frame)?.spring(k)?.fixed(frame.inverse())
    }

    /// Finishes the model.
    pub fn build(self) -> Result<Model, BuildError> {
        Ok(Model {
            elements: self.elements,
            dof: self.dof,
            springs: self.springs,
        })
    }
}

fn iso_is_finite(t: &Isometry3<f64>) -> bool {
    t.translation.vector.iter().all(|v| v.is_finite())
        && t.rotation.coords.iter().all(|v| v.is_finite())
}

/// Per-call workspace and the last call's by-products, sized once for any model
/// (fixed capacities, so creating one allocates nothing).
#[derive(Debug, Clone)]
pub struct Data {
    /// Rigid TCP pose of the last call, base frame.
    pub tcp: Isometry3<f64>,
    /// Deflected TCP pose of the last [`crate::vjm::deflection`] call, base frame (Eq. 8).
    pub tcp_deflected: Isometry3<f64>,
    /// Elastic angles `[alpha, beta, gamma]` [rad] of each spring from the last
    /// [`crate::vjm::deflection`] call (Eq. 7), in chain order; entries past
    /// [`Model::spring_count`] are zero.
    pub spring_angles: [Vector3<f64>; MAX_SPRINGS],
    /// Actuated-joint Jacobian `[v; w]` of the TCP [m/rad or 1, rad/rad], base frame, from the
    /// last [`crate::vjm::joint_jacobian`] call; columns past [`Model::dof`] are zero.
    pub jacobian: SMatrix<f64, 6, MAX_DOF>,
    /// Cartesian compliance of the last [`crate::vjm::compliance`] call.
    pub compliance: Matrix6<f64>,
}

impl Data {
    /// A workspace for `model` (any model fits; the argument keeps the pinocchio shape).
    pub fn new(_model: &Model) -> Self {
        Self {
            tcp: Isometry3::identity(),
            tcp_deflected: Isometry3::identity(),
            spring_angles: [Vector3::zeros(); MAX_SPRINGS],
            jacobian: SMatrix::zeros(),
            compliance: Matrix6::zeros(),
        }
    }
}
