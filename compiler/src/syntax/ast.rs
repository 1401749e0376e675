//! The abstract syntax tree, exactly as written, with a span on every node.
//!
//! The tree is never rewritten after parsing: analyses keep their results in
//! side tables keyed by [`NodeId`] (see `check`), as naga's `ModuleInfo` does.
//!
//! Expressions and statements are dropped iteratively (see [`Expr`]'s and
//! [`Stmt`]'s `Drop`): a tree of any depth, such as a sum of 100,000 terms,
//! can be freed, even one that the nesting limits (`crate::limits`) reject.
//! Everything else that walks the tree recursively runs only after those
//! limits have bounded its depth.

pub use crate::span::Span;

/// Identifies an expression or statement; dense, starting at 0, in parse order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeId(pub u32);

/// Hands out [`NodeId`]s while parsing.
#[derive(Debug, Default)]
pub struct IdGen(std::cell::Cell<u32>);

impl IdGen {
    pub fn next(&self) -> NodeId {
        let id = self.0.get();
        self.0.set(id + 1);
        NodeId(id)
    }
    pub fn count(&self) -> u32 {
        self.0.get()
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct Ident {
    pub name: String,
    pub span: Span,
}

/// `@name` or `@name(args)` before a declaration.
#[derive(Debug, Clone, PartialEq)]
pub struct Attribute {
    pub name: Ident,
    pub args: Vec<Expr>,
    pub span: Span,
}

/// A type as written: a name, resolved by the checker.
pub type TypeName = Ident;

#[derive(Debug, Clone, PartialEq)]
pub struct Program {
    pub items: Vec<Item>,
    /// How many [`NodeId`]s the parser handed out.
    pub node_count: u32,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Item {
    Input(InputDecl),
    Uniform(UniformDecl),
    Const(ConstDecl),
    Function(FunctionDecl),
    Effect(EffectDecl),
}

impl Item {
    pub fn name(&self) -> &Ident {
        match self {
            Item::Input(d) => &d.name,
            Item::Uniform(d) => &d.name,
            Item::Const(d) => &d.name,
            Item::Function(d) => &d.name,
            Item::Effect(d) => &d.name,
        }
    }
}

/// `in float3 normal;`: a G-buffer channel.
#[derive(Debug, Clone, PartialEq)]
pub struct InputDecl {
    pub attrs: Vec<Attribute>,
    pub ty: TypeName,
    pub name: Ident,
    pub span: Span,
}

/// `uniform float x = 1.0;`, `uniform float4 lights[8];`, `uniform texture2d t;`.
#[derive(Debug, Clone, PartialEq)]
pub struct UniformDecl {
    pub attrs: Vec<Attribute>,
    pub ty: TypeName,
    pub name: Ident,
    pub array_len: Option<Expr>,
    pub default: Option<Expr>,
    /// An array's default, `= { a, b, ... }`.
    pub elements: Option<Elements>,
    pub span: Span,
}

/// The elements of an array default, `{ a, b, ... }`.
#[derive(Debug, Clone, PartialEq)]
pub struct Elements {
    pub items: Vec<Expr>,
    pub span: Span,
}

#[derive(Debug, Clone, PartialEq)]
pub struct ConstDecl {
    pub ty: TypeName,
    pub name: Ident,
    pub value: Expr,
    pub span: Span,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Param {
    pub ty: TypeName,
    pub name: Ident,
}

#[derive(Debug, Clone, PartialEq)]
pub struct FunctionDecl {
    pub ret: TypeName,
    pub name: Ident,
    pub params: Vec<Param>,
    pub body: Block,
    pub span: Span,
}

/// The rate of an effect (part of the layout contract).
pub use mrsl_abi::Rate;

#[derive(Debug, Clone, PartialEq)]
pub enum EffectBody {
    /// `= expr;`
    Expr(Expr),
    /// `{ statements }`, assigning the effect's own name.
    Block(Block),
}

#[derive(Debug, Clone, PartialEq)]
pub struct EffectDecl {
    pub attrs: Vec<Attribute>,
    pub rate: Rate,
    /// The span of the rate keywords (`coarse effect`, `coarse(4) effect`, `fine out`).
    pub rate_span: Span,
    /// `coarse(N)`: the block size N as written, and its span; `None` for
    /// plain `coarse` and the fine rates.
    pub coarse_block: Option<(u64, Span)>,
    pub ty: TypeName,
    pub name: Ident,
    pub body: EffectBody,
    pub span: Span,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Block {
    pub stmts: Vec<Stmt>,
    pub span: Span,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Stmt {
    pub id: NodeId,
    pub span: Span,
    pub kind: StmtKind,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AssignOp {
    Set,
    Add,
    Sub,
    Mul,
    Div,
}

#[derive(Debug, Clone, PartialEq)]
pub enum StmtKind {
    /// `float x = e;` or `float x;` (zero-initialised).
    Local {
        ty: TypeName,
        name: Ident,
        init: Option<Expr>,
    },
    /// `target op= value;`
    Assign {
        target: Expr,
        op: AssignOp,
        value: Expr,
    },
    /// `x++` / `x--` (as statements only).
    Step {
        target: Expr,
        increment: bool,
    },
    If {
        cond: Expr,
        then: Box<Stmt>,
        otherwise: Option<Box<Stmt>>,
    },
    For {
        init: Option<Box<Stmt>>,
        cond: Option<Expr>,
        step: Option<Box<Stmt>>,
        body: Box<Stmt>,
    },
    Block(Block),
    Refine,
    Return(Option<Expr>),
    Break,
    Continue,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum UnaryOp {
    Neg,
    /// Unary `+`: checked like `-`, emitted as its operand.
    Pos,
    Not,
    BitNot,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BinaryOp {
    Add,
    Sub,
    Mul,
    Div,
    Rem,
    Shl,
    Shr,
    BitAnd,
    BitOr,
    BitXor,
    And,
    Or,
    Eq,
    Ne,
    Lt,
    Gt,
    Le,
    Ge,
}

impl BinaryOp {
    pub fn symbol(self) -> &'static str {
        use BinaryOp::*;
        match self {
            Add => "+",
            Sub => "-",
            Mul => "*",
            Div => "/",
            Rem => "%",
            Shl => "<<",
            Shr => ">>",
            BitAnd => "&",
            BitOr => "|",
            BitXor => "^",
            And => "&&",
            Or => "||",
            Eq => "==",
            Ne => "!=",
            Lt => "<",
            Gt => ">",
            Le => "<=",
            Ge => ">=",
        }
    }
}

/// Integer literal suffix: none (adapts to context), `u` or `i`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IntSuffix {
    None,
    U,
    I,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Expr {
    pub id: NodeId,
    pub span: Span,
    pub kind: ExprKind,
}

/// Frees the children of deep trees without recursion: each node's children
/// are moved onto an explicit stack before the node itself is dropped, so the
/// derived recursive drop only ever sees childless nodes.
impl Drop for Expr {
    fn drop(&mut self) {
        let mut pending = Orphans::default();
        pending.take_expr(&mut self.kind);
        pending.drain();
    }
}

impl Drop for Stmt {
    fn drop(&mut self) {
        let mut pending = Orphans::default();
        pending.take_stmt(&mut self.kind);
        pending.drain();
    }
}

/// The children taken out of nodes being dropped, waiting to be dropped.
#[derive(Default)]
struct Orphans {
    exprs: Vec<Expr>,
    stmts: Vec<Stmt>,
}

impl Orphans {
    fn take_expr(&mut self, kind: &mut ExprKind) {
        if matches!(kind, ExprKind::Int(..) | ExprKind::Float(_) | ExprKind::Bool(_) | ExprKind::Name(_)) {
            return;
        }
        match std::mem::replace(kind, ExprKind::Bool(false)) {
            ExprKind::Unary(_, a) | ExprKind::Field { base: a, .. } => self.exprs.push(*a),
            ExprKind::Binary(_, a, b) | ExprKind::Index { base: a, index: b } => {
                self.exprs.push(*a);
                self.exprs.push(*b);
            }
            ExprKind::Ternary(a, b, c) => {
                self.exprs.push(*a);
                self.exprs.push(*b);
                self.exprs.push(*c);
            }
            ExprKind::Call { args, .. } => self.exprs.extend(args),
            ExprKind::Int(..) | ExprKind::Float(_) | ExprKind::Bool(_) | ExprKind::Name(_) => {}
        }
    }

    fn take_stmt(&mut self, kind: &mut StmtKind) {
        if matches!(kind, StmtKind::Refine | StmtKind::Break | StmtKind::Continue | StmtKind::Return(None)) {
            return;
        }
        match std::mem::replace(kind, StmtKind::Break) {
            StmtKind::Local { init, .. } => self.exprs.extend(init),
            StmtKind::Assign { target, value, .. } => {
                self.exprs.push(target);
                self.exprs.push(value);
            }
            StmtKind::Step { target, .. } => self.exprs.push(target),
            StmtKind::If { cond, then, otherwise } => {
                self.exprs.push(cond);
                self.stmts.push(*then);
                self.stmts.extend(otherwise.map(|o| *o));
            }
            StmtKind::For { init, cond, step, body } => {
                self.stmts.extend(init.map(|s| *s));
                self.exprs.extend(cond);
                self.stmts.extend(step.map(|s| *s));
                self.stmts.push(*body);
            }
            StmtKind::Block(b) => self.stmts.extend(b.stmts),
            StmtKind::Return(e) => self.exprs.extend(e),
            StmtKind::Refine | StmtKind::Break | StmtKind::Continue => {}
        }
    }

    /// Drops everything taken, taking the children of each node first.
    fn drain(&mut self) {
        loop {
            if let Some(mut e) = self.exprs.pop() {
                self.take_expr(&mut e.kind);
            } else if let Some(mut s) = self.stmts.pop() {
                self.take_stmt(&mut s.kind);
            } else {
                break;
            }
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub enum ExprKind {
    Int(u64, IntSuffix),
    Float(f64),
    Bool(bool),
    Name(String),
    Unary(UnaryOp, Box<Expr>),
    Binary(BinaryOp, Box<Expr>, Box<Expr>),
    Ternary(Box<Expr>, Box<Expr>, Box<Expr>),
    Call { callee: Ident, args: Vec<Expr> },
    Field { base: Box<Expr>, field: Ident },
    Index { base: Box<Expr>, index: Box<Expr> },
}
