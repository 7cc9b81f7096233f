//! Counting a lobe's shader instructions for the GPU cost model
//! ([`specula::gpu_cost`]): the exported lobe (constants baked in) is parsed and validated by
//! naga, and the statements of `specula_lobe` and every function it calls are walked, each
//! emitted expression counted once by class. The walk is over naga's IR, from which naga
//! emits SPIR-V one instruction per arithmetic expression, because the IR keeps the loops'
//! structure: the only loops in `lobes.wgsl` are the squaring loops, which run
//! `lobe.squarings` times, so their bodies count that many times, without the counter's
//! integer work (the trip count is baked in, and compilers unroll such loops). Of an `if`,
//! the costlier branch counts (a divergent warp runs both; a uniform one, at most that).

use naga::{
    BinaryOperator, Block, Expression, Handle, MathFunction, Module, ScalarKind, Statement,
};
use specula::gpu_cost::ShaderOps;
use specula::{Geometry, Lobe, Normalisation};

use crate::export::export_wgsl_source;
use crate::wgsl;

/// The instructions of `lobe`'s exported shader, per evaluation.
pub fn lobe_shader_ops(lobe: &Lobe) -> Result<ShaderOps, String> {
    let source = export_wgsl_source(lobe, Geometry::Phong, Normalisation::None);
    let (module, info) = wgsl::validate(&source)?;
    let counter = Counter {
        module: &module,
        info: &info,
        trips: lobe.packed().squarings,
    };
    let entry = find(&module, "specula_lobe").ok_or("no specula_lobe in the exported shader")?;
    Ok(counter.function(entry))
}

fn find(module: &Module, name: &str) -> Option<Handle<naga::Function>> {
    module
        .functions
        .iter()
        .find(|(_, f)| f.name.as_deref() == Some(name))
        .map(|(handle, _)| handle)
}

struct Counter<'a> {
    module: &'a Module,
    info: &'a naga::valid::ModuleInfo,
    trips: u32,
}

impl Counter<'_> {
    fn function(&self, handle: Handle<naga::Function>) -> ShaderOps {
        self.block(handle, &self.module.functions[handle].body)
    }

    fn block(&self, function: Handle<naga::Function>, block: &Block) -> ShaderOps {
        block.iter().fold(ShaderOps::default(), |sum, statement| {
            sum + self.statement(function, statement)
        })
    }

    fn statement(&self, function: Handle<naga::Function>, statement: &Statement) -> ShaderOps {
        match statement {
            Statement::Emit(range) => range.clone().fold(ShaderOps::default(), |sum, e| {
                sum + self.expression(function, e)
            }),
            Statement::Block(block) => self.block(function, block),
            Statement::If { accept, reject, .. } => {
                let (a, b) = (self.block(function, accept), self.block(function, reject));
                if a.expanded().total() >= b.expanded().total() {
                    a
                } else {
                    b
                }
            }
            Statement::Loop {
                body, continuing, ..
            } => {
                let trip = self.block(function, body) + self.block(function, continuing);
                // The trip count is a baked constant: compilers unroll the loop, and its
                // counter's increment and exit test (its only integer work) vanish.
                ShaderOps { integer: 0, ..trip } * self.trips
            }
            Statement::Call {
                function: callee, ..
            } => self.function(*callee),
            _ => ShaderOps::default(),
        }
    }

    fn expression(
        &self,
        function: Handle<naga::Function>,
        handle: Handle<Expression>,
    ) -> ShaderOps {
        let f = &self.module.functions[function];
        let is_float = || {
            self.info[function][handle]
                .ty
                .inner_with(&self.module.types)
                .scalar_kind()
                == Some(ScalarKind::Float)
        };
        let operand_is_float = |operand: Handle<Expression>| {
            self.info[function][operand]
                .ty
                .inner_with(&self.module.types)
                .scalar_kind()
                == Some(ScalarKind::Float)
        };
        let mut ops = ShaderOps::default();
        match &f.expressions[handle] {
            Expression::Binary { op, left, .. } => match op {
                BinaryOperator::Add | BinaryOperator::Subtract | BinaryOperator::Multiply => {
                    if is_float() {
                        ops.arithmetic = 1;
                    } else {
                        ops.integer = 1;
                    }
                }
                BinaryOperator::Divide => {
                    ops.transcendental = 1;
                    ops.arithmetic = 1;
                }
                BinaryOperator::Less
                | BinaryOperator::LessEqual
                | BinaryOperator::Greater
                | BinaryOperator::GreaterEqual
                | BinaryOperator::Equal
                | BinaryOperator::NotEqual => {
                    if operand_is_float(*left) {
                        ops.compare = 1;
                    } else {
                        ops.integer = 1;
                    }
                }
                _ => ops.integer = 1,
            },
            Expression::Unary { .. } | Expression::Relational { .. } => ops.compare = 1,
            Expression::Select { .. } => ops.compare = 1,
            Expression::As {
                convert: Some(_), ..
            } => ops.conversion = 1,
            Expression::Math { fun, .. } => match fun {
                MathFunction::Exp2 | MathFunction::Log2 | MathFunction::Sqrt => {
                    ops.transcendental = 1;
                }
                MathFunction::InverseSqrt => ops.transcendental = 1,
                MathFunction::Pow => {
                    ops.transcendental = 2;
                    ops.arithmetic = 1;
                }
                MathFunction::Acos => ops.acos = 1,
                MathFunction::Min | MathFunction::Max | MathFunction::Clamp => ops.compare = 1,
                MathFunction::Floor | MathFunction::Ceil | MathFunction::Trunc => {
                    ops.conversion = 1;
                }
                MathFunction::Abs => {}
                _ => ops.arithmetic = 1,
            },
            _ => {}
        }
        ops
    }
}
