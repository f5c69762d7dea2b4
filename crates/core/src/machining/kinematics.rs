//! A five-axis machine's rotary axes: how a G-code program's `A B C` angles turn into the tool
//! axis and the tool tip in the workpiece frame.
//!
//! Two rotary axes, each on the table (it turns the workpiece) or on the head (it turns the
//! spindle): table-table (a trunnion carrying a rotary table, `A C` or `B C`), head-head (a
//! fork head, `B C` or `A C`), head-table (`B` on the head, `C` on the table). Each turns
//! positively about its `direction` (right hand) through its `point` (machine frame, with
//! every rotary at 0); of two axes on the same carrier the first is mounted on the machine and
//! carries the second. With every rotary at 0 the tool axis is the machine's `+z` and the
//! workpiece frame is the machine frame.
//!
//! The linear axes `X Y Z` are either the tool tip in the workpiece frame (`tcp`: the
//! control's tool centre point management, LinuxCNC's TCP kinematics, Heidenhain's `M128`,
//! Siemens' `TRAORI`, Fanuc's `G43.4`: what most five-axis posts for such controls write), or
//! the machine's axes (`tcp` off): then the tip is where the machine's chain puts it, the
//! head's rotaries turning the tool about their points, the table's turning the workpiece
//! under it. A table axis' point is in the machine frame (the workpiece frame at 0); a head
//! axis' point is relative to the tool tip with every axis at 0 (a fork head's pivot `L`
//! above the tip: `(0, 0, L)`), carried by the linear axes. Between two points of a program
//! the move is straight in the workpiece frame (with `tcp` the control makes it so; without,
//! the machine's own path between the points differs by its chord, which five-axis posts
//! keep small with dense points).

use nalgebra::{Rotation3, Unit, Vector3};

use crate::error::BuildError;

/// Which rotary word an axis reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RotaryWord {
    /// `A` (about x on most machines).
    A,
    /// `B` (about y).
    B,
    /// `C` (about z).
    C,
}

impl RotaryWord {
    /// "A", "B" or "C".
    pub fn name(self) -> &'static str {
        match self {
            Self::A => "A",
            Self::B => "B",
            Self::C => "C",
        }
    }

    /// 0, 1, 2 for A, B, C.
    pub fn index(self) -> usize {
        match self {
            Self::A => 0,
            Self::B => 1,
            Self::C => 2,
        }
    }
}

/// What a rotary axis turns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Carrier {
    /// The table: it turns the workpiece.
    Table,
    /// The head: it turns the spindle.
    Head,
}

/// One rotary axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rotary {
    /// The word it reads (its angle in degrees in the program).
    pub word: RotaryWord,
    /// Table or head.
    pub carrier: Carrier,
    /// Its direction (unit after [`Kinematics::new`]), machine frame, every rotary at 0.
    pub direction: Vector3<f64>,
    /// A point on it \[m\], machine frame, every rotary at 0.
    pub point: Vector3<f64>,
    /// Its travel \[rad\], `lower < upper`: an angle outside cannot be reached.
    pub limits: (f64, f64),
}

impl Rotary {
    fn rotation(&self, angle: f64) -> Rotation3<f64> {
        Rotation3::from_axis_angle(&Unit::new_unchecked(self.direction), angle)
    }
}

/// A five-axis machine's two rotary axes and how its linear axes are read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kinematics {
    rotaries: [Rotary; 2],
    tcp: bool,
}

/// A pose of the tool in the workpiece frame: tip \[m\] and axis (unit, tip towards spindle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolPose {
    /// The tool tip \[m\].
    pub tip: Vector3<f64>,
    /// The tool axis, unit.
    pub axis: Vector3<f64>,
}

impl Kinematics {
    /// Checked kinematics: two rotaries of different words, each direction finite and
    /// non-zero (normalised), points finite within 1000 m, limits finite with `lower <
    /// upper` within +-100 turns; of a table and a head, either order (the table's is applied
    /// to the workpiece, the head's to the tool). [`BuildError::InvalidParameter`] naming what
    /// is wrong.
    pub fn new(rotaries: [Rotary; 2], tcp: bool) -> Result<Self, BuildError> {
        let [a, b] = rotaries;
        if a.word == b.word {
            return Err(BuildError::InvalidParameter {
                what: "rotary axes (the same word twice)",
                value: a.word.index() as f64,
                expected: "two different words of A, B, C",
            });
        }
        let mut out = rotaries;
        for r in &mut out {
            let n = r.direction.norm();
            crate::error::param(
                "rotary axis direction (its length)",
                n,
                n > 1e-12,
                "a finite, non-zero direction",
            )?;
            r.direction /= n;
            for v in r.point.iter() {
                crate::error::param(
                    "rotary axis point",
                    *v,
                    v.abs() <= 1.0e3, // MAX_COORDINATE: a robot cell is metres
                    "finite, within +-1000 m",
                )?;
            }
            let turns = 200.0 * core::f64::consts::PI;
            crate::error::param(
                "rotary axis lower limit",
                r.limits.0,
                r.limits.0 >= -turns && r.limits.0 < r.limits.1,
                "finite, below the upper limit, within +-100 turns (rad)",
            )?;
            crate::error::param(
                "rotary axis upper limit",
                r.limits.1,
                r.limits.1 <= turns,
                "finite, within +-100 turns (rad)",
            )?;
        }
        Ok(Self { rotaries: out, tcp })
    }

    /// The two rotaries as given (directions unit).
    pub fn rotaries(&self) -> &[Rotary; 2] {
        &self.rotaries
    }

    /// Whether `X Y Z` are the tool tip in the workpiece frame.
    pub fn tcp(&self) -> bool {
        self.tcp
    }

    /// The rotary reading `word`, if the machine has it.
    pub fn rotary(&self, word: RotaryWord) -> Option<&Rotary> {
        self.rotaries.iter().find(|r| r.word == word)
    }

    /// The rotation and translation of the carrier's chain (`Table` or `Head`) at `angles`
    /// \[rad\] (indexed by A, B, C): `p -> R p + t`, the first axis outermost.
    fn chain(&self, carrier: Carrier, angles: &[f64; 3]) -> (Rotation3<f64>, Vector3<f64>) {
        let mut rot = Rotation3::identity();
        let mut t = Vector3::zeros();
        // Outermost first: p_machine = R1 (R2 (p - c2) + c2 - c1) + c1.
        for r in self.rotaries.iter().filter(|r| r.carrier == carrier) {
            let angle = angles.get(r.word.index()).copied().unwrap_or(0.0);
            let ri = r.rotation(angle);
            // (rot, t) composed with the rotation about r's line: x -> ri (x - c) + c, applied
            // inside the chain built so far.
            let c = r.point;
            t += rot * (c - ri * c);
            rot *= ri;
        }
        (rot, t)
    }

    /// The tool pose in the workpiece frame for the linear axes `xyz` \[m\] and the rotary
    /// angles `angles` \[rad\] (A, B, C; a word the machine does not have is read as 0).
    /// [`BuildError::InvalidParameter`] naming the rotary whose angle is outside its limits
    /// (the angle in the message's value).
    pub fn pose(&self, xyz: &Vector3<f64>, angles: &[f64; 3]) -> Result<ToolPose, BuildError> {
        for r in &self.rotaries {
            let a = angles.get(r.word.index()).copied().unwrap_or(0.0);
            if !(a >= r.limits.0 && a <= r.limits.1) {
                return Err(BuildError::InvalidParameter {
                    what: match r.word {
                        RotaryWord::A => "A angle (outside the axis' limits)",
                        RotaryWord::B => "B angle (outside the axis' limits)",
                        RotaryWord::C => "C angle (outside the axis' limits)",
                    },
                    value: a,
                    expected: "within the rotary axis' limits (rad)",
                });
            }
        }
        let (table, table_t) = self.chain(Carrier::Table, angles);
        let (head, head_t) = self.chain(Carrier::Head, angles);
        // The head's turn of the spindle direction; the table's of the workpiece.
        let axis_machine = head * Vector3::z();
        let axis = table.inverse() * axis_machine;
        if self.tcp {
            return Ok(ToolPose { tip: *xyz, axis });
        }
        // Machine axes: the head's chain moves the tip (its origin) to `head_t`, carried by
        // the linear axes; the table's chain is undone on the machine point.
        let tip_machine = xyz + head_t;
        let tip = table.inverse() * (tip_machine - table_t);
        Ok(ToolPose { tip, axis })
    }
}
